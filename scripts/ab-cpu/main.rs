//! The harness of `scripts/ab-cpu.sh` (see there): the same rays through an old commit's CPU
//! backend (`oc`, `ocpu`) and the working tree's (`rc`, `rcpu`), one thread, interleaved rounds.
//!
//! Rays: primary rays of the bench's outside or inside view (the conformance suite's
//! `Camera::inside`, as the bench's), their diffuse bounces, shadow rays to the default light,
//! and ambient-occlusion rays (the bounces cut to 5% of the scene's diagonal).

use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

/// Ends the run with `msg` (the inputs are the script's arguments: a bad one is a usage error).
fn die(msg: String) -> ! {
    eprintln!("ab-cpu: {msg}");
    std::process::exit(2)
}

/// Traces `rays` `times` times with the new side: with `AB_COUNT`, the one function
/// `scripts/instr-profile.sh` has callgrind count instructions in.
#[inline(never)]
fn counted(
    b: &rcpu::CpuBackend,
    s: &rcpu::CpuScene,
    rays: &[rc::Ray],
    opts: &rc::trace::TraceOptions,
    hits: &mut [rc::Hit],
    times: usize,
) {
    use rc::trace::Trace;
    for _ in 0..times {
        b.trace(s, rays, opts, hits).unwrap();
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let Some(path) = args.get(1) else { die("usage: SCENE [VIEW] [METHOD] [ROUNDS] [SETS]".into()) };
    let view = args.get(2).map(String::as_str).unwrap_or("inside");
    let method = args.get(3).map(String::as_str).unwrap_or("bvh8").to_string();
    let rounds: usize = args.get(4).and_then(|s| s.parse().ok()).unwrap_or(15);
    let sets_wanted: Vec<String> = args.get(5).map(|s| s.split(',').map(String::from).collect()).unwrap_or(vec![
        "primary".into(),
        "shadow".into(),
        "diffuse".into(),
        "ao".into(),
    ]);
    let (w, h): (u32, u32) = std::env::var("AB_SIZE")
        .ok()
        .and_then(|s| {
            let (a, b) = s.split_once("x")?;
            Some((a.parse().ok()?, b.parse().ok()?))
        })
        .unwrap_or((384, 288));

    // New side.
    let mesh = rmesh::load(Path::new(path)).unwrap_or_else(|e| die(e.to_string()));
    let scene = mesh.to_scene().unwrap_or_else(|e| die(format!("{path}: {e}")));
    let mut cfg = rc::bvh2::SahConfig::default();
    let envf = |k: &str| std::env::var(k).ok().and_then(|v| v.parse::<f32>().ok());
    if let Some(t) = envf("AB_TRAV") {
        cfg.traversal_cost = t;
    }
    if let Some(t) = envf("AB_MAXLEAF") {
        cfg.max_leaf_size = t as u32;
    }
    if let Some(t) = envf("AB_BLOCK") {
        cfg.leaf_block = t as u32;
    }
    if let Some(t) = envf("AB_BINS") {
        cfg.bins = t as usize;
    }
    let bvh = rc::bvh2::SahBuilder { config: cfg }.build(scene.triangles()).unwrap();
    eprintln!("new tree: {:?}", bvh.stats());
    // AB_NEW_METHOD=NAME: the new side traces with another method than the old (bvh8-packet
    // against bvh8, say); its hits must still be the old method's.
    let new_method = std::env::var("AB_NEW_METHOD").unwrap_or_else(|_| method.clone());
    let m = rc::method::Method::from_name(&new_method).unwrap_or_else(|| die(format!("unknown method {new_method}")));
    let newb = rcpu::CpuBackend::with_threads(1).unwrap();
    use rc::trace::Trace;
    let new_side =
        || newb.prepare(Arc::new(rc::prepared::PreparedScene::new(&scene, bvh.clone(), &[m]).unwrap())).unwrap();
    let mut ns = new_side();
    // Old side.
    // The new side's loader for both: the old commit may keep its loaders in another crate. Both
    // sides' meshes are positions and index triples of the workspace's glam.
    let omesh = oc::scene::Mesh { positions: mesh.positions.clone(), triangles: mesh.triangles.clone() };
    let oscene = omesh.to_scene().unwrap();
    let obvh = oc::bvh2::SahBuilder::default().build(oscene.triangles()).unwrap();
    let om = oc::method::Method::from_name(&method)
        .unwrap_or_else(|| die(format!("{method}: not a method of the old commit")));
    let oldb = ocpu::CpuBackend::with_threads(1).unwrap();
    use oc::trace::Trace as OTrace;
    let old_side =
        || oldb.prepare(Arc::new(oc::prepared::PreparedScene::new(&oscene, obvh.clone(), &[om]).unwrap())).unwrap();
    let mut os = old_side();
    // Each round traces fresh copies of both trees (AB_FRESH=0: the same copies throughout): where
    // a process's allocations land in physical memory moved a ray set's time by up to 25% from
    // one run to the next, and fresh copies each round let the median average that out.
    let fresh = std::env::var("AB_FRESH").map_or(true, |v| v != "0");

    let bounds = scene.bounds();
    let cam = if view == "inside" { conf::rays::Camera::inside(bounds) } else { conf::rays::Camera::framing(bounds) };
    let mut prim = conf::rays::primary_from(&cam, w, h);
    // AB_TILES=1: the camera rays (and so the rays made from their hits) in tiles of 8 x 8 pixels,
    // the tiles in row order, as a tiled renderer hands them over.
    if std::env::var("AB_TILES").is_ok() && w % 8 == 0 && h % 8 == 0 {
        let (w, h) = (w as usize, h as usize);
        let tile = |i: usize| {
            let (t, k) = (i / 64, i % 64);
            let (tx, ty) = (t % (w / 8), t / (w / 8));
            (ty * 8 + k / 8) * w + tx * 8 + k % 8
        };
        prim = (0..w * h).map(|i| prim[tile(i)]).collect();
    }
    let mut hits = vec![rc::Hit::MISS; prim.len()];
    newb.trace(&ns, &prim, &rc::trace::TraceOptions::new(m), &mut hits).unwrap();
    let diff = conf::rays::diffuse(&prim, &hits, &scene, conf::rays::RAY_SEED);
    let sh = conf::rays::shadow(&prim, &hits, conf::rays::default_light(bounds), conf::rays::scene_epsilon(bounds));
    let radius = 0.05 * bounds.extent().length();
    let ao: Vec<rc::Ray> = diff.iter().map(|r| rc::Ray::new(r.origin(), r.dir(), r.tmin, radius)).collect();
    let mut all = [("primary", prim, false), ("shadow", sh, true), ("diffuse", diff, false), ("ao", ao, true)];
    // AB_SHUFFLE=1: the shadow, diffuse and AO rays shuffled by a fixed seed, as the bench's
    // `--order shuffled` and a path tracer's later bounces come.
    if std::env::var("AB_SHUFFLE").is_ok_and(|v| v == "1") {
        for (k, set) in all.iter_mut().enumerate().skip(1) {
            conf::rng::Pcg32::new(conf::rays::RAY_SEED, k as u64).shuffle(&mut set.1);
        }
    }
    for (name, rays, any) in all.iter() {
        if !sets_wanted.iter().any(|s| s == name) {
            continue;
        }
        let orays: Vec<oc::Ray> =
            rays.iter().map(|r| oc::Ray { origin: r.origin, tmin: r.tmin, dir: r.dir, tmax: r.tmax }).collect();
        let q = if *any { rc::method::Query::Any } else { rc::method::Query::Closest };
        let oq = if *any { oc::method::Query::Any } else { oc::method::Query::Closest };
        let (mut nopts, mut oopts) =
            (rc::trace::TraceOptions::new(m).query(q), oc::trace::TraceOptions::new(om).query(oq));
        // AB_SORTED=1: both sides trace the batch sorted (`TraceOrder::Sorted`, the sort inside
        // the timed and counted call; the old commit must have it).
        if std::env::var("AB_SORTED").is_ok_and(|v| v == "1") {
            nopts = nopts.order(rc::trace_order::TraceOrder::Sorted);
            oopts = oopts.order(oc::trace_order::TraceOrder::Sorted);
        }
        let mut nh = vec![rc::Hit::MISS; rays.len()];
        let mut oh = vec![oc::Hit::MISS; rays.len()];
        if let Some(times) = std::env::var("AB_COUNT").ok().and_then(|v| v.parse::<usize>().ok()) {
            newb.trace(&ns, rays, &nopts, &mut nh).unwrap();
            counted(&newb, &ns, rays, &nopts, &mut nh, times);
            println!("{name:8} {:>8} rays traced {times} times (AB_COUNT) by the new side", rays.len());
            continue;
        }
        let (mut tn, mut to) = (Vec::new(), Vec::new());
        for r in 0..rounds + 1 {
            if fresh && r > 0 {
                os = old_side();
                ns = new_side();
            }
            let mut run_old = || {
                let s = Instant::now();
                oldb.trace(&os, &orays, &oopts, &mut oh).unwrap();
                s.elapsed().as_secs_f64()
            };
            let mut run_new = || {
                let s = Instant::now();
                newb.trace(&ns, rays, &nopts, &mut nh).unwrap();
                s.elapsed().as_secs_f64()
            };
            let (a, b) = if r % 2 == 0 {
                let a = run_old();
                (a, run_new())
            } else {
                let b = run_new();
                (run_old(), b)
            };
            if r > 0 {
                to.push(a);
                tn.push(b);
            }
        }
        let cn = newb
            .trace(&ns, rays, &nopts.clone().record(rc::trace::Record::Counters), &mut nh)
            .unwrap()
            .counters
            .unwrap();
        let co = oldb
            .trace(&os, &orays, &oopts.clone().record(oc::trace::Record::Counters), &mut oh)
            .unwrap()
            .counters
            .unwrap();
        let n = rays.len() as f64;
        println!(
            "{name:8} work/ray  old nodes {:.2} leaves {:.2} tests {:.2} | new nodes {:.2} leaves {:.2} tests {:.2}",
            co.internal_nodes as f64 / n,
            co.leaves as f64 / n,
            co.primitive_tests as f64 / n,
            cn.internal_nodes as f64 / n,
            cn.leaves as f64 / n,
            cn.primitive_tests as f64 / n
        );
        let same = nh.iter().zip(&oh).all(|(a, b)| a.t.to_bits() == b.t.to_bits() && a.prim == b.prim);
        let med = |v: &mut Vec<f64>| {
            v.sort_by(|a, b| a.partial_cmp(b).unwrap());
            v[v.len() / 2]
        };
        let (mo, mn) = (med(&mut to), med(&mut tn));
        let mut ratios: Vec<f64> = to.iter().zip(&tn).map(|(a, b)| a / b).collect();
        let mr = med(&mut ratios);
        println!("{name:8} {:>8} rays  old {:7.2} ms  new {:7.2} ms  new/old speed {:.3} (per-round median {:.3})  same={same}",
            rays.len(), mo * 1e3, mn * 1e3, mo / mn, mr);
    }
}
