//! `raytrail-hwsim`: compares raytrail's traversal methods stepped in lockstep warps.

use raytrail_core::method::{Bvh2Method, KdMethod, Method, StreamMethod, Structure};
use raytrail_hwsim::stream_lanes::{self, simulate_stream, Packing};
use raytrail_hwsim::{report, simulate, RayKind, Scenario, SimConfig};
use std::path::Path;

const USAGE: &str = "\
raytrail-hwsim: raytrail's traversal methods stepped in lockstep warps (a SIMT model)

USAGE:
  raytrail-hwsim [--scene FILE|builtin] [--width W] [--height H] [--warp N]
                 [--rays primary|shadow|diffuse] [--methods a,b,...] [--timeline METHOD]

  --scene     OBJ or PLY mesh (a path, or a file name in the shared scenes folder);
              builtin (default): the generated sphereflake of depth 3
  --width, --height
              camera resolution, default 256 x 192; shadow and diffuse rays start at its hits
  --warp      lanes per warp, default 32
  --rays      ray set, default primary (closest hit); shadow rays are any-hit queries
  --methods   methods to compare (names, or the groups bvh2, kd, wide), default all of them:
              bvh2: stack, stack-disjoint, parent-sibling, uncle, hash, hash-disjoint, hash-resume
              kd: kd-stack, kd-restart, kd-push-down, kd-short-stack (kd-packet is not simulated:
                  a packet of four rays is a lockstep unit of its own)
              wide: bvh4, bvh8, bvh4-naive, bvh8-sah (the packet and stream methods are not simulated, as kd-packet)
              stream: Garanzha & Loop's sorted packets, modelled per warp of a packet's rays,
                  sorted and (for comparison) packed in input order
  --timeline  also print the slowest warp's cycles for METHOD, one symbol per lane:
              . idle, i internal node, l leaf; backtracks: s stack pop, r register, h hash,
              w walk over links, x restart (upper case: after a leaf)";

/// The methods the simulator steps: every method whose rays walk alone (the stream method has a
/// model of its own, `stream_lanes`).
fn simulated() -> Vec<Method> {
    Method::ALL
        .into_iter()
        .filter(|&m| m != Method::Kd(KdMethod::Packet) && m.wide().is_none_or(|w| !w.walk().shares_walks()))
        .collect()
}

/// The methods of a name or a group name.
fn methods_of(name: &str) -> Result<Vec<Method>, String> {
    let group = |s: Structure| simulated().into_iter().filter(|m| m.structure() == s).collect();
    match name {
        "bvh2" => Ok(group(Structure::Bvh2)),
        "kd" => Ok(group(Structure::Kd)),
        "wide" => Ok(group(Structure::Wide)),
        "all" => Ok(simulated()),
        "stream" => Ok(vec![Method::Stream(StreamMethod::Frustum8)]),
        _ => Method::from_name(name).map(|m| vec![m]).ok_or_else(|| format!("unknown method '{name}'")),
    }
}

struct Args {
    scene: String,
    width: u32,
    height: u32,
    warp: usize,
    rays: RayKind,
    methods: Vec<Method>,
    timeline: Option<Method>,
}

fn parse(args: &[String]) -> Result<Option<Args>, String> {
    let mut a = Args {
        scene: "builtin".into(),
        width: 256,
        height: 192,
        warp: 32,
        rays: RayKind::Primary,
        methods: simulated(),
        timeline: None,
    };
    let mut it = args.iter();
    while let Some(flag) = it.next() {
        if flag == "-h" || flag == "--help" {
            return Ok(None);
        }
        let value = it.next().ok_or_else(|| format!("{flag} needs a value"))?;
        let number = |what: &str| value.parse::<u32>().map_err(|_| format!("{what}: '{value}' is not a count"));
        let method = |name: &str| Method::from_name(name).ok_or_else(|| format!("unknown method '{name}'"));
        match flag.as_str() {
            "--scene" => a.scene = value.clone(),
            "--width" => a.width = number("--width")?,
            "--height" => a.height = number("--height")?,
            "--warp" => a.warp = number("--warp")? as usize,
            "--rays" => a.rays = RayKind::from_name(value).ok_or_else(|| format!("unknown ray set '{value}'"))?,
            "--methods" => {
                a.methods = value.split(',').map(methods_of).collect::<Result<Vec<_>, _>>()?.concat();
            }
            "--timeline" => a.timeline = Some(method(value)?),
            other => return Err(format!("unknown option '{other}'")),
        }
    }
    if a.width == 0 || a.height == 0 || a.warp == 0 {
        return Err("--width, --height and --warp must be at least 1".into());
    }
    Ok(Some(a))
}

/// The built-in sphereflake, a mesh at a path, or a mesh by name in the shared scenes folder.
fn load(scene: &str) -> Result<(String, raytrail_core::scene::Scene), String> {
    if scene == "builtin" {
        return Ok(("sphereflake(3)".into(), raytrail_conformance::scenes::sphereflake(3)));
    }
    // `load_mesh_scene` resolves names against the scenes folder; an existing path is taken as is.
    let file = match Path::new(scene).canonicalize() {
        Ok(p) if p.is_file() => p.to_string_lossy().into_owned(),
        _ => scene.to_string(),
    };
    raytrail_conformance::paths::load_mesh_scene(&file).map(|s| (s.name, s.scene)).map_err(|e| e.to_string())
}

fn run(a: &Args) -> Result<(), String> {
    let (name, scene) = load(&a.scene)?;
    let s = Scenario::new(scene, a.rays, a.width, a.height).map_err(|e| e.to_string())?;
    let stats = s.prepared.bvh.stats();
    println!(
        "scene {name}: {} triangles; SAH tree: {} internal nodes, {} leaves, depth {}, {} keys",
        s.scene.triangles().len(),
        stats.internal_nodes,
        stats.leaves,
        stats.depth,
        stats.key_width
    );
    println!("{}", report::structures(&s.prepared));
    let query = a.rays.query();
    println!(
        "rays: {} {} ({} x {} camera), {} hit; watertight triangle test\n",
        s.rays.len(),
        a.rays.name(),
        a.width,
        a.height,
        query.name()
    );
    let mut reports = Vec::new();
    let mut timeline = None;
    let mut stream_rows = Vec::new();
    for &m in &a.methods {
        if m.stream().is_some() {
            for packing in [Packing::Sorted, Packing::InputOrder] {
                let (r, _) =
                    simulate_stream(&s.prepared, &s.rays, query, a.warp, packing).map_err(|e| e.to_string())?;
                stream_rows.push((packing, r));
            }
            continue;
        }
        let cfg = SimConfig { warp: a.warp, record_timeline: a.timeline == Some(m), ..SimConfig::new(query) };
        let run = simulate(&s.prepared, m, &s.rays, &cfg).map_err(|e| e.to_string())?;
        if cfg.record_timeline {
            timeline = Some((m, run.timeline));
        }
        reports.push(run.report);
    }
    print!("{}", report::tables(&reports));
    if !stream_rows.is_empty() {
        println!(
            "\nstream (Garanzha & Loop 2010): each packet's rays in warps stepping through its leaf list together\n\
             (a box test per leaf for every lane, the leaf's triangles for the lanes that enter it):"
        );
        print!("{}", stream_lanes::table(&stream_rows));
    }
    if reports.iter().any(|r| r.method == Method::Bvh2(Bvh2Method::HashResume)) {
        println!(
            "  hash-resume runs in lockstep too: a lane pauses after each leaf with a hit and resumes from key and\n  \
             trail within the same cycle; the resume's hash lookup counts as hash traffic."
        );
    }
    if let Some((m, cycles)) = timeline {
        println!(
            "\nSlowest warp, {m}, one row per cycle (. idle, i internal, l leaf;\nbacktracks s pop, r register, h hash, w walk, x restart, upper case after a leaf):"
        );
        print!("{}", report::timeline(&cycles));
    }
    Ok(())
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let parsed = match parse(&args) {
        Ok(Some(a)) => a,
        Ok(None) => {
            println!("{USAGE}");
            return;
        }
        Err(e) => {
            eprintln!("error: {e}\n\n{USAGE}");
            std::process::exit(2);
        }
    };
    if let Err(e) = run(&parsed) {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}
