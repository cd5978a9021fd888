//! The `raytrail` command line: the main job (no arguments), `trace`, `rays` and `bench`.

mod args;
mod bench;
mod gpu;
mod median;
mod progress;
mod run;
mod trace;

const USAGE: &str = "\
raytrail: ray-traversal methods for triangle scenes

USAGE:
  raytrail                      the main job on the built-in scene (same as `raytrail run`)
  raytrail run [--scene FILE] [--builder sah|ploc] [--width W] [--height H] [--passes N]
               [--threads N] [--check-rays N] [--no-gpu] [--strict]
      builds the BVH, derives layouts and hash tables, traces primary, shadow and diffuse rays
      with every method on the CPU and, when wgpu finds an adapter, on the GPU, and prints
      Mrays/s, work per ray, state size and the conformance verdict
  raytrail trace --scene FILE --rays RAYS.npy --method NAME --out HITS.npy [--any]
               [--builder sah|ploc] [--moller-trumbore] [--strict] [--prim-map FILE.csv]
      traces a NumPy ray file (float32, shape (N, 8): origin xyz, tmin, dir xyz, tmax) into a hit
      file (fields t <f4, prim <u4, u <f4, v <f4; a miss has t = inf, prim = 0xFFFFFFFF);
      --prim-map writes where in the mesh file each primitive id comes from
  raytrail rays --scene FILE --out RAYS.npy [--width W] [--height H] [--strict]
      writes primary rays (Morton order) framing the scene, for `trace`
  raytrail bench [--scene FILE[,FILE...]] [--rays primary,shadow,diffuse,ao] [--width W] [--height H]
               [--passes N] [--threads N[,N...]] [--methods NAME,...|all|none] [--peers NAME,...|all|none]
               [--baseline NAME] [--builder sah|ploc] [--ao-rays N] [--view outside|inside|both|auto]
               [--json FILE] [--plot FILE.svg] [--strict]
      times raytrail's methods and the peers (obvhs-bvh2, obvhs-cwbvh, bvh; each also as NAME+wt with
      raytrail's watertight test; embree, own test only, in a binary built with `--features embree`)
      on the same rays on the same thread pool; prints Mrays/s (median of N passes, default 5, after
      a warm-up), the ratio to the baseline (default obvhs-bvh2), work per ray, build times, memory
      and hit agreement with the stack method. Views: the camera outside the scene framing it, or
      inside it (low in its box, looking along the long side, 90-degree field of view); `auto` adds
      the inside view where it sees a room. Defaults: 512 x 512 primary rays, 4 ambient-occlusion
      rays per hit, 1 thread and all threads, every method and peer, --view auto

METHODS: stack, stack-disjoint, parent-sibling, uncle, hash, hash-disjoint, hash-resume (BVH2);
         kd-stack, kd-restart, kd-push-down, kd-short-stack, kd-packet (kd-tree);
         bvh4, bvh8, bvh4-naive (wide BVH)
SCENES:  OBJ, PLY (ASCII or binary), OFF, STL (ASCII or binary), glTF 2.0 (.gltf, .glb), any of them
         gzip-compressed; `builtin` is a generated sphereflake. Elements that are not triangles or
         polygons (2-vertex faces, OBJ lines and points) are skipped with one warning line;
         --strict makes them an error";

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    // `--help` anywhere (`raytrail bench --help`) prints the usage rather than a parse error.
    if args.iter().any(|a| a == "-h" || a == "--help") {
        println!("{USAGE}");
        return;
    }
    let (cmd, rest) = match args.first().map(String::as_str) {
        None => ("run", &args[..]),
        Some("-h" | "--help" | "help") => {
            println!("{USAGE}");
            return;
        }
        Some(c) if c.starts_with("--") => ("run", &args[..]),
        Some(c) => (c, &args[1..]),
    };
    let result = match cmd {
        "run" => run::main(rest),
        "trace" => trace::main(rest),
        "rays" => trace::rays_main(rest),
        "bench" => bench::main(rest),
        other => Err(format!("unknown command '{other}'\n\n{USAGE}")),
    };
    match result {
        Ok(0) => {}
        Ok(code) => std::process::exit(code),
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(2);
        }
    }
}
