//! The command line's commands and their flags, declared with clap (derive), and the mesh loading
//! that `--strict` and `--prim-map` shape, shared by the commands that take `--scene` (flags
//! several commands share are in [`crate::flags`]; why a command fails, in [`crate::failure`]).

use crate::failure::{usage, Failure};
use crate::flags::{method_names_or_auto, LoadFlags, AUTO, BUILDERS, BUILTIN_SCENE, STRICT};
use clap::{Parser, Subcommand};
use raytrail::mesh::{write_sources_csv, LoadOptions, LoadReport};
use raytrail::Builder;
use raytrail_cli::write::same_file;
use raytrail_conformance::NamedScene;
use std::ffi::{OsStr, OsString};
use std::path::{Path, PathBuf};

const AFTER_HELP: &str = "\
METHODS: stack, stack-disjoint, parent-sibling, uncle, hash, hash-disjoint, hash-resume (BVH2);
         kd-stack, kd-restart, kd-push-down, kd-short-stack, kd-packet (kd-tree);
         bvh4, bvh8, bvh4-naive, bvh8-sah, bvh8-packet, bvh8-lists, bvh4-hash, bvh8-sah-packet,
         bvh8-sah-lists (wide BVH; bvh8-stream and bvh8-sah-stream, the lists' former names, still
         work);
         stream (ray stream, Garanzha & Loop);
         auto (trace's default; bench --methods): the fastest of bvh8-sah, bvh8-sah-packet,
         bvh8-sah-lists, bvh8-packet, bvh8-lists and kd-stack
         timed on a sample of the rays (`raytrail explain SCENE` shows the choice per ray type)
SCENES:  OBJ, PLY (ASCII or binary), OFF, STL (ASCII or binary), glTF 2.0 (.gltf, .glb), any of them
         gzip-compressed; `builtin` is a generated sphereflake. Elements that are not triangles or
         polygons (2-vertex faces, OBJ lines and points) are skipped with one warning line;
         --strict makes them an error
EXIT STATUS: 0 done; 1 a failure while working (or a failed conformance check); 2 a usage error";

/// `raytrail`: ray-traversal methods for triangle scenes.
#[derive(Parser, Debug)]
#[command(
    name = "raytrail",
    version,
    about = "raytrail: ray-traversal methods for triangle scenes",
    long_about = "raytrail: ray-traversal methods for triangle scenes.\n\nWithout a subcommand, runs the main job \
                  (`raytrail run`) with the flags given.",
    after_help = AFTER_HELP,
    args_conflicts_with_subcommands = true,
    subcommand_negates_reqs = true
)]
pub struct Cli {
    /// The subcommand; none is `run`.
    #[command(subcommand)]
    pub command: Option<Command>,
    /// `run`'s flags, for `raytrail` without a subcommand.
    #[command(flatten)]
    pub run: RunArgs,
}

/// The subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// The main job: every method timed and checked on one scene (the default command)
    ///
    /// Builds the BVH, derives layouts and hash tables, traces primary, shadow and diffuse rays
    /// with every method on the CPU and (when wgpu finds an adapter) on the GPU, and prints
    /// Mrays/s, work per ray, state size and the conformance verdict.
    #[command(after_help = AFTER_HELP)]
    Run(RunArgs),
    /// Traces a NumPy ray file into a NumPy hit file
    #[command(
        long_about = "Traces a NumPy ray file (float32, shape (N, 8): origin xyz, tmin, dir xyz, tmax) into a hit \
                      file (fields t <f4, prim <u4, u <f4, v <f4; a miss has t = inf, prim = 0xFFFFFFFF), hit i \
                      for ray i.",
        after_help = AFTER_HELP
    )]
    Trace(TraceArgs),
    /// The nearest point on the mesh to each point of a NumPy point file
    #[command(
        long_about = "The nearest point on the mesh to each point of a NumPy point file (float, shape (N, 3)), \
                      within --radius: a file of records (fields prim <u4, distance <f4, x y z <f4, u v <f4; \
                      where no triangle is within the radius, prim = 0xFFFFFFFF and distance = inf), record i for \
                      point i.",
        after_help = AFTER_HELP
    )]
    Nearest(NearestArgs),
    /// Writes primary rays framing the scene, for `trace`
    #[command(
        long_about = "Writes primary rays framing the scene (a NumPy file for `trace`). --order morton (the default) \
                      writes them in Morton (Z-curve) order of their pixels, which traces faster; --order raster \
                      writes them row by row, top-left first, so ray i is pixel (i % width, i / width). For Morton \
                      order, the pixel of ray i is the i-th pixel in the Z-curve over the smallest power-of-two \
                      square holding the image, pixels outside the image skipped.",
        after_help = AFTER_HELP
    )]
    Rays(RaysArgs),
    /// Times raytrail's methods and the peer libraries on the same rays
    #[command(
        long_about = "Times raytrail's methods and the peers (obvhs-bvh2, obvhs-cwbvh, bvh; each also as NAME+wt \
                      with raytrail's watertight test; embree and embree-high, Embree's default and high build \
                      qualities, own test only, in a binary built with `--features embree`; `--baseline \
                      embree-best` takes the faster of the two per batch) on the same rays on the same thread pool; prints Mrays/s (median of N passes after a \
                      warm-up), the ratio to the baseline, work per ray, build times, memory and hit agreement with \
                      the stack method. Views: the camera outside the scene framing it, or inside it (low in its \
                      box, looking along the long side, 90-degree field of view); `auto` adds the inside view where \
                      it sees a room.",
        after_help = AFTER_HELP
    )]
    Bench(crate::bench::options::BenchArgs),
    /// Tells what a scene needs: tables and their sizes, features, kernels, a method per ray type
    #[command(
        long_about = "Analyses a scene: every table each method would build (bytes, build time), whether 64-bit keys, \
                      hash tables, the f64 fallback, the disjoint mask and the slack are needed, which wgpu kernels \
                      would be compiled, and which method to use per ray type, chosen by timing a few candidates on a \
                      sample of the rays on the CPU (what --method auto does). Without --rays, the bench's ray types \
                      (primary, shadow, soft-shadow, diffuse, ao) from the outside view, and the inside view where \
                      it sees a room.",
        after_help = AFTER_HELP
    )]
    Explain(ExplainArgs),
    /// Runs the numerics stress suite and reports, per case, rays agreeing with the exact reference
    #[command(
        long_about = "Runs the numerics stress suite: rays at shared vertices and edges of closed meshes, grazing \
                      and axis-parallel rays, origins up to 1e8 scene diameters away, scenes scaled from 1e-30 to \
                      1e30 and translated up to 1e7 diameters, subnormal coordinates, tiny triangles beside huge \
                      ones, and the edges of the supported range (docs/NUMERICS-RANGE.md). Every method traces \
                      every case on the CPU (and on the GPU when wgpu finds an adapter), and every ray is judged \
                      against an exact reference. Exit status 1 when any ray disagrees.",
        after_help = AFTER_HELP
    )]
    Stress(StressArgs),
    /// Renders the scene to a PNG: normals, ambient occlusion, or a heat map of traversal work
    ///
    /// Primary rays in raster order through the outside or inside camera; the image shows the hit
    /// triangles' normals, ambient occlusion, or a heat map of the traversal work per pixel (nodes
    /// visited, or backtracking steps) of any --method, so that methods can be compared by eye.
    #[command(after_help = AFTER_HELP)]
    Render(RenderArgs),
    /// Run time against error: every method and triangle test timed, and judged against the exact
    /// reference
    #[command(
        long_about = "Times every method with every triangle test on the CPU (all threads; Mrays/s, median of \
                      --passes on the full ray set) and judges a sample of each ray set against the exact reference \
                      (integer arithmetic on the f32 inputs): false misses, false hits, wrong primitives, t beyond \
                      the tolerance, and the t error in ulps. Prints a table per scene and ray type with the Pareto \
                      front of speed against error marked; --json and --plot write the results and an SVG plot.",
        after_help = AFTER_HELP
    )]
    Accuracy(AccuracyArgs),
}

/// The triangle tests `raytrail accuracy` can measure, by command-line name.
pub const TRIANGLE_TESTS: [&str; 2] = ["watertight", "moller-trumbore"];

/// `raytrail accuracy`.
#[derive(clap::Args, Debug, Clone)]
pub struct AccuracyArgs {
    /// Scene files (or `builtin`), comma-separated (the flag may also be repeated)
    #[arg(long, short = 's', value_name = "FILE[,FILE...]", default_value = BUILTIN_SCENE, action = clap::ArgAction::Append)]
    pub scene: Vec<OsString>,
    /// Ray types, comma-separated: primary, shadow, soft-shadow, diffuse, ao
    #[arg(long, value_name = "TYPE[,TYPE...]", value_delimiter = ',', default_value = "primary,shadow,diffuse,ao")]
    pub rays: Vec<String>,
    /// Methods, comma-separated, or all
    #[arg(long, value_name = "NAME[,NAME...]|all", value_delimiter = ',', default_value = "all")]
    pub methods: Vec<String>,
    /// Triangle tests, comma-separated: watertight, moller-trumbore
    #[arg(long, value_name = "TEST[,TEST...]", value_delimiter = ',', default_value = "watertight,moller-trumbore",
          value_parser = TRIANGLE_TESTS)]
    pub tests: Vec<String>,
    /// Primary image width
    #[arg(long, short = 'W', default_value_t = 320, value_parser = clap::value_parser!(u32).range(1..))]
    pub width: u32,
    /// Primary image height
    #[arg(long, short = 'H', default_value_t = 240, value_parser = clap::value_parser!(u32).range(1..))]
    pub height: u32,
    /// Rays per ray set judged against the exact reference (evenly spaced over the set)
    #[arg(long, value_name = "N", default_value_t = 4096, value_parser = clap::value_parser!(u64).range(1..))]
    pub sample: u64,
    /// Timed passes per method and test, after one untimed pass (the median is reported)
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..))]
    pub passes: u32,
    /// Ambient-occlusion rays per primary hit
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub ao_rays: u32,
    /// Camera views: outside, inside, both, or auto (inside too where it sees a room)
    #[arg(long, default_value = "auto", value_parser = ["outside", "inside", "both", "auto"])]
    pub view: String,
    /// BVH2 builder: `best` builds with both and keeps the tree of the lower SAH cost
    #[arg(long, default_value = "best", value_parser = BUILDERS)]
    pub builder: String,
    /// Also write the results as JSON
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Also write an SVG plot of Mrays/s against error rate, the Pareto front marked
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
    /// Most rays per ray set
    #[arg(long, value_name = "N", default_value_t = crate::limits::DEFAULT_MAX_RAYS)]
    pub max_rays: u64,
    #[command(flatten)]
    pub load: LoadFlags,
}

/// `raytrail run`.
#[derive(clap::Args, Debug, Clone)]
pub struct RunArgs {
    /// Scene file, or `builtin`
    #[arg(long, short = 's', value_name = "FILE", default_value = BUILTIN_SCENE)]
    pub scene: PathBuf,
    /// BVH2 builder: `best` builds with both and keeps the tree of the lower SAH cost
    #[arg(long, default_value = "best", value_parser = BUILDERS)]
    pub builder: String,
    /// Primary image width
    #[arg(long, short = 'W', default_value_t = 320, value_parser = clap::value_parser!(u32).range(1..))]
    pub width: u32,
    /// Primary image height
    #[arg(long, short = 'H', default_value_t = 240, value_parser = clap::value_parser!(u32).range(1..))]
    pub height: u32,
    /// Timed passes per method (the median is reported)
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..))]
    pub passes: u32,
    /// Worker threads [default: all]
    #[arg(long, short = 'j', value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    /// Rays per set checked for conformance (hits and node enumerations)
    #[arg(long, default_value_t = 8192)]
    pub check_rays: usize,
    /// Leave the GPU out even when wgpu finds an adapter
    #[arg(long)]
    pub no_gpu: bool,
    /// Most rays per ray set (each set holds one ray per pixel)
    #[arg(long, value_name = "N", default_value_t = crate::limits::DEFAULT_MAX_RAYS)]
    pub max_rays: u64,
    #[command(flatten)]
    pub load: LoadFlags,
}

/// `raytrail trace`.
#[derive(clap::Args, Debug, Clone)]
pub struct TraceArgs {
    /// Scene file, or `builtin`
    #[arg(long, short = 's', value_name = "FILE")]
    pub scene: PathBuf,
    /// The NumPy ray file to trace
    #[arg(long, value_name = "RAYS.npy")]
    pub rays: PathBuf,
    /// Traversal method, or auto: the fastest of a few candidates timed on a sample of the rays
    #[arg(long, short = 'm', default_value = AUTO, value_parser = method_names_or_auto(), hide_possible_values = true)]
    pub method: String,
    /// The NumPy hit file to write
    #[arg(long, short = 'o', value_name = "HITS.npy")]
    pub out: PathBuf,
    /// Any-hit (occlusion) queries instead of closest-hit
    #[arg(long)]
    pub any: bool,
    /// Every hit along each ray, in order of t, instead of the closest: one record per hit, with
    /// its ray's index (fields ray <u4, t, prim, u, v), from the 8-wide tree of least node area
    #[arg(long, conflicts_with_all = ["any", "moller_trumbore"])]
    pub all: bool,
    /// With --all: at most this many hits per ray, the nearest (the rays with more are counted)
    #[arg(long, value_name = "N", requires = "all")]
    pub max_hits: Option<usize>,
    /// With --all: hits at the same t count once (the lower primitive id)
    #[arg(long, requires = "all")]
    pub merge_equal_t: bool,
    /// BVH2 builder: `best` builds with both and keeps the tree of the lower SAH cost
    #[arg(long, default_value = "best", value_parser = BUILDERS)]
    pub builder: String,
    /// Möller-Trumbore triangle test instead of the watertight one
    #[arg(long)]
    pub moller_trumbore: bool,
    /// Also write where in the mesh file each primitive id comes from (CSV: prim,file,<where>)
    #[arg(long, value_name = "FILE.csv")]
    pub prim_map: Option<PathBuf>,
    /// For a scene file of instances: a NumPy file of one unsigned mask per ray (shape (N,));
    /// a ray enters only the instances whose mask shares a bit with its own (all bits where
    /// left out)
    #[arg(long, value_name = "MASKS.npy")]
    pub masks: Option<PathBuf>,
    /// Most rays the ray file may hold
    #[arg(long, value_name = "N", default_value_t = crate::limits::DEFAULT_MAX_RAYS)]
    pub max_rays: u64,
    #[command(flatten)]
    pub load: LoadFlags,
}

/// `raytrail nearest`.
#[derive(clap::Args, Debug, Clone)]
pub struct NearestArgs {
    /// Scene file, or `builtin`
    #[arg(long, short = 's', value_name = "FILE")]
    pub scene: PathBuf,
    /// The NumPy point file (float, shape (N, 3))
    #[arg(long, value_name = "POINTS.npy")]
    pub points: PathBuf,
    /// The NumPy file of nearest points to write
    #[arg(long, short = 'o', value_name = "NEAREST.npy")]
    pub out: PathBuf,
    /// Search radius: points with no triangle this close get none
    #[arg(long, default_value_t = f32::INFINITY, value_parser = non_negative_f32)]
    pub radius: f32,
    /// BVH2 builder: `best` builds with both and keeps the tree of the lower SAH cost
    #[arg(long, default_value = "best", value_parser = BUILDERS)]
    pub builder: String,
    /// Most points the point file may hold
    #[arg(long, value_name = "N", default_value_t = crate::limits::DEFAULT_MAX_RAYS)]
    pub max_points: u64,
    #[command(flatten)]
    pub load: LoadFlags,
}

/// A number that is zero or more (infinity allowed), for `--radius`.
fn non_negative_f32(s: &str) -> Result<f32, String> {
    let x: f32 = s.parse().map_err(|_| format!("{s:?} is not a number"))?;
    if x.is_nan() || x < 0.0 {
        return Err(format!("{s} is not zero or more"));
    }
    Ok(x)
}

/// `raytrail stress`.
#[derive(clap::Args, Debug, Clone)]
pub struct StressArgs {
    /// Leave the GPU out even when wgpu finds an adapter
    #[arg(long)]
    pub no_gpu: bool,
}

/// `raytrail explain`.
#[derive(clap::Args, Debug, Clone)]
pub struct ExplainArgs {
    /// Scene file, or `builtin`
    #[arg(value_name = "SCENE")]
    pub scene: PathBuf,
    /// A NumPy ray file to choose a method for (instead of the generated ray types)
    #[arg(long, value_name = "RAYS.npy")]
    pub rays: Option<PathBuf>,
    /// The --rays are any-hit (occlusion) queries
    #[arg(long, requires = "rays")]
    pub any: bool,
    /// Also write the analysis as JSON
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// BVH2 builder: `best` builds with both and keeps the tree of the lower SAH cost
    #[arg(long, default_value = "best", value_parser = BUILDERS)]
    pub builder: String,
    /// Width of the generated primary image
    #[arg(long, short = 'W', default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..))]
    pub width: u32,
    /// Height of the generated primary image
    #[arg(long, short = 'H', default_value_t = 192, value_parser = clap::value_parser!(u32).range(1..))]
    pub height: u32,
    /// Camera views of the generated rays: outside, inside, both, or auto (inside too where it sees a room)
    #[arg(long, default_value = "auto", value_parser = ["outside", "inside", "both", "auto"])]
    pub view: String,
    /// Most rays per set
    #[arg(long, value_name = "N", default_value_t = crate::limits::DEFAULT_MAX_RAYS)]
    pub max_rays: u64,
    #[command(flatten)]
    pub load: LoadFlags,
}

/// Ray orders of `raytrail rays`.
pub const ORDERS: [&str; 2] = ["morton", "raster"];

/// `raytrail rays`.
#[derive(clap::Args, Debug, Clone)]
pub struct RaysArgs {
    /// Scene file, or `builtin`
    #[arg(long, short = 's', value_name = "FILE")]
    pub scene: PathBuf,
    /// The NumPy ray file to write
    #[arg(long, short = 'o', value_name = "RAYS.npy")]
    pub out: PathBuf,
    /// Image width
    #[arg(long, short = 'W', default_value_t = 320, value_parser = clap::value_parser!(u32).range(1..))]
    pub width: u32,
    /// Image height
    #[arg(long, short = 'H', default_value_t = 240, value_parser = clap::value_parser!(u32).range(1..))]
    pub height: u32,
    /// Ray order: morton (Z-curve over the pixels, faster to trace) or raster (row by row, top-left
    /// first: ray i is pixel (i % width, i / width))
    #[arg(long, default_value = "morton", value_parser = ORDERS)]
    pub order: String,
    /// Most rays (width x height)
    #[arg(long, value_name = "N", default_value_t = crate::limits::DEFAULT_MAX_RAYS)]
    pub max_rays: u64,
    #[command(flatten)]
    pub load: LoadFlags,
}

/// What `raytrail render` draws.
pub const RENDER_MODES: [&str; 4] = ["normals", "ao", "heat", "backtracks"];

/// `raytrail render`.
#[derive(clap::Args, Debug, Clone)]
pub struct RenderArgs {
    /// Scene file, or `builtin`
    #[arg(long, short = 's', value_name = "FILE", default_value = BUILTIN_SCENE)]
    pub scene: PathBuf,
    /// The PNG file to write
    #[arg(long, short = 'o', value_name = "IMAGE.png")]
    pub out: PathBuf,
    /// What to draw: normals (shaded by the hit triangle's normal), ao (ambient occlusion), heat
    /// (nodes visited per pixel by --method) or backtracks (backtracking steps per pixel by
    /// --method); heat maps run on a log scale from dark blue (none) to red (the image's most)
    #[arg(long, default_value = "normals", value_parser = RENDER_MODES)]
    pub mode: String,
    /// Image width
    #[arg(long, short = 'W', default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..))]
    pub width: u32,
    /// Image height
    #[arg(long, short = 'H', default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..))]
    pub height: u32,
    /// Camera: outside (framing the scene) or inside (low in its box, looking along the long side)
    #[arg(long, default_value = "outside", value_parser = ["outside", "inside"])]
    pub camera: String,
    /// Traversal method, or auto: the fastest of a few candidates timed on a sample of the image's
    /// rays
    #[arg(long, short = 'm', default_value = "stack", value_parser = method_names_or_auto(), hide_possible_values = true)]
    pub method: String,
    /// Backend for normals and ao: cpu, or gpu (wgpu, when it finds an adapter); heat maps run on
    /// the CPU
    #[arg(long, default_value = "cpu", value_parser = ["cpu", "gpu"])]
    pub backend: String,
    /// BVH2 builder: `best` builds with both and keeps the tree of the lower SAH cost
    #[arg(long, default_value = "best", value_parser = BUILDERS)]
    pub builder: String,
    /// Ambient-occlusion rays per pixel (--mode ao)
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..=256))]
    pub ao_rays: u32,
    /// Most pixels (width x height)
    #[arg(long, value_name = "N", default_value_t = crate::limits::DEFAULT_MAX_PIXELS)]
    pub max_pixels: u64,
    #[command(flatten)]
    pub load: LoadFlags,
}

/// Says on standard error when `--builder ploc` builds `scene` with the SAH builder instead
/// (triangles collapsed to one point, which PLOC clusters in quadratic time).
pub fn ploc_note(builder: Builder, scene: &raytrail::core::scene::Scene) {
    if builder == Builder::Ploc {
        if let Some(why) = raytrail::build::ploc::ploc_fallback(scene.triangles()) {
            errln!("warning: --builder ploc: {why}");
        }
    }
}

/// A comma-separated list of paths as the system gave it (on Unix, bytes that are not UTF-8
/// kept): split at each comma, each trimmed of ASCII white space, empty ones left out.
pub fn path_list(list: &OsStr) -> Vec<PathBuf> {
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        list.as_bytes()
            .split(|&b| b == b',')
            .map(<[u8]>::trim_ascii)
            .filter(|p| !p.is_empty())
            .map(|p| PathBuf::from(OsStr::from_bytes(p)))
            .collect()
    }
    #[cfg(not(unix))]
    {
        list.to_string_lossy().split(',').map(str::trim).filter(|p| !p.is_empty()).map(PathBuf::from).collect()
    }
}

/// Whether `path` names the built-in scene rather than a file.
pub fn is_builtin(path: &Path) -> bool {
    path.as_os_str() == BUILTIN_SCENE
}

/// Checks that `path` can be written as an output: its folder exists and it is not a folder.
pub fn check_output(flag: &str, path: &Path) -> Result<(), Failure> {
    let shown = path.display();
    if path.as_os_str().is_empty() {
        return usage(format!("--{flag}: empty path"));
    }
    if path.is_dir() {
        return usage(format!("--{flag}: cannot write {shown}: it is a folder"));
    }
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if !dir.is_dir() {
        return usage(format!("--{flag}: cannot write {shown}: its folder {} does not exist", dir.display()));
    }
    Ok(())
}

/// Checks that the input file `path` exists (`builtin` is no file): a failure (exit status 1)
/// found before any work, saying what the path is when it is there but no file.
pub fn check_input(flag: &str, path: &Path) -> Result<(), Failure> {
    if is_builtin(path) {
        return Ok(());
    }
    use std::os::unix::fs::FileTypeExt;
    let shown = path.display();
    let what = match std::fs::metadata(path) {
        Ok(m) if m.is_file() => return Ok(()),
        // A pipe (`--scene <(zcat mesh.obj.gz)`) is read as a stream.
        Ok(m) if m.file_type().is_fifo() => return Ok(()),
        Ok(m) if m.is_dir() => "it is a folder, not a file",
        Ok(_) => "it is a device, not a file or a pipe",
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => "no such file",
        Err(e) => return Err(Failure::Run(format!("--{flag}: {shown}: {e}"))),
    };
    Err(Failure::Run(format!("--{flag}: {shown}: {what}")))
}

/// Refuses, before any work, an output that is one of the command's inputs (the same file by
/// device and inode, however it is spelled or linked: `trace --out` naming the ray file would
/// destroy it), or the same file as another output. Devices and pipes (`/dev/null`) may be named
/// more than once.
pub fn check_distinct(inputs: &[(&str, &Path)], outputs: &[(&str, &Path)]) -> Result<(), Failure> {
    for (i, &(flag, path)) in outputs.iter().enumerate() {
        for &(input_flag, input) in inputs {
            if !is_builtin(input) && same_file(path, input) {
                return usage(format!(
                    "--{flag} {} is the input --{input_flag} {}: writing it would destroy the input; name another file",
                    path.display(),
                    input.display()
                ));
            }
        }
        for &(other_flag, other) in &outputs[i + 1..] {
            if same_output(path, other) {
                return usage(format!(
                    "--{flag} and --{other_flag} name one file ({}): one would overwrite the other",
                    path.display()
                ));
            }
        }
    }
    Ok(())
}

/// Whether two outputs name one regular file, whether or not it exists yet.
fn same_output(a: &Path, b: &Path) -> bool {
    let regular = |p: &Path| std::fs::metadata(p).map_or(true, |m| m.is_file());
    if !regular(a) || !regular(b) {
        return false;
    }
    // Not there yet: the same folder (by identity) and the same name.
    let folder = |p: &Path| p.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new(".")).to_path_buf();
    same_file(a, b) || (a.file_name() == b.file_name() && same_file(folder(a), folder(b)))
}

/// Loads a scene (a mesh file or `builtin`) with `options`; returns the warning line to print
/// when loading skipped elements (print it with [`warn`] once any progress line is done).
pub fn load_scene(path: &Path, options: &LoadOptions) -> Result<(NamedScene, LoadReport, Option<String>), String> {
    if is_builtin(path) {
        return Ok((builtin_scene(), LoadReport::default(), None));
    }
    let shown = path.display();
    let (mesh, report) = raytrail::mesh::load_with(path, options).map_err(|e| e.to_string())?;
    let scene = mesh.to_scene().map_err(|e| match report.skipped {
        0 => format!("{shown}: {e}"),
        1 => format!("{shown}: {e} (1 element that is not a triangle or polygon was skipped)"),
        n => format!("{shown}: {e} ({n} elements that are not triangles or polygons were skipped)"),
    })?;
    let name = path.file_name().map_or(shown.to_string(), |n| n.to_string_lossy().into_owned());
    let warning = skipped_warning(&shown.to_string(), &report);
    Ok((NamedScene::new(name, scene), report, warning))
}

/// The built-in scene ([`BUILTIN_SCENE`]).
pub fn builtin_scene() -> NamedScene {
    raytrail_conformance::suite::generated_scene("sphereflake")
}

/// The one warning line for what loading `path` skipped, if it skipped anything.
pub fn skipped_warning(path: &str, report: &LoadReport) -> Option<String> {
    report.summary(path).map(|s| format!("warning: {s} (--{STRICT} makes this an error)"))
}

/// Prints a warning line, if there is one, on standard error.
pub fn warn(warning: &Option<String>) {
    if let Some(w) = warning {
        errln!("{w}");
    }
}

/// Writes the primitive-id map (`--prim-map`): CSV `prim,file,<where>`, one row per triangle.
pub fn write_prim_map(out: &Path, scene: &Path, report: &LoadReport) -> Result<(), String> {
    let scene = scene.display().to_string();
    raytrail_cli::write::write_atomically(out, |w| write_sources_csv(w, &scene, &report.sources))
        .map_err(|e| format!("cannot write {}: {e}", out.display()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use raytrail::core::method::Method;

    fn args(s: &str) -> LoadFlags {
        let cli =
            Cli::try_parse_from(format!("raytrail rays --scene a.obj --out r.npy {s}").split_whitespace()).unwrap();
        match cli.command {
            Some(Command::Rays(r)) => r.load,
            other => panic!("{other:?}"),
        }
    }

    /// A scratch folder of the test's own, removed when the test ends.
    fn scratch_folder() -> tempfile::TempDir {
        tempfile::Builder::new().prefix("raytrail-cli-args-").tempdir().unwrap()
    }

    /// A file named `name` holding `data` in `dir`.
    fn scratch(dir: &tempfile::TempDir, name: &str, data: &[u8]) -> String {
        let path = dir.path().join(name);
        std::fs::write(&path, data).unwrap();
        path.display().to_string()
    }

    const OBJ: &[u8] = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\nl 1 2 3\np 1\nf 1 2 3\n";

    #[test]
    fn the_command_line_is_consistent() {
        use clap::CommandFactory;
        Cli::command().debug_assert();
    }

    #[test]
    fn strict_switch() {
        assert!(!args("").load_options().strict);
        assert!(args("--strict").load_options().strict);
        assert!(!args("--strict").load_options().sources);
    }

    #[test]
    fn lenient_load_warns_once_and_strict_fails() {
        let dir = scratch_folder();
        let path = scratch(&dir, "edges.obj", OBJ);
        let (named, report, warning) = load_scene(Path::new(&path), &args("").load_options()).unwrap();
        assert_eq!(named.scene.triangles().len(), 1);
        assert_eq!(report.skipped, 3);
        assert_eq!(
            warning.unwrap(),
            format!(
                "warning: {path}: skipped 3 elements that are not triangles or polygons, the first at line 4: \
                 a face with 2 vertices (--strict makes this an error)"
            )
        );
        let e = load_scene(Path::new(&path), &args("--strict").load_options()).unwrap_err();
        assert_eq!(e, format!("{path}:4: face has 2 vertices; a face needs at least 3"));
        // Nothing skipped: no warning.
        let clean = scratch(&dir, "clean.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
        assert_eq!(load_scene(Path::new(&clean), &LoadOptions::default()).unwrap().2, None);
    }

    #[test]
    fn prim_map_file() {
        let dir = scratch_folder();
        let path = scratch(&dir, "map.obj", OBJ);
        let options = LoadOptions { sources: true, ..LoadOptions::default() };
        let (_, report, _) = load_scene(Path::new(&path), &options).unwrap();
        let out = scratch(&dir, "map.csv", b"");
        write_prim_map(Path::new(&out), Path::new(&path), &report).unwrap();
        assert_eq!(std::fs::read_to_string(&out).unwrap(), format!("prim,file,line\n0,{path},7\n"));
        let e = write_prim_map(Path::new("/nonexistent/dir/map.csv"), Path::new(&path), &report).unwrap_err();
        assert!(e.starts_with("cannot write /nonexistent/dir/map.csv: "), "{e}");
    }

    #[test]
    fn help_lists_every_method() {
        // The list in the help is written by hand; this keeps it in step with the methods.
        let listed: Vec<&str> =
            AFTER_HELP.split(|c: char| !(c.is_ascii_alphanumeric() || c == '-')).filter(|w| !w.is_empty()).collect();
        for method in Method::ALL {
            assert!(listed.contains(&method.name()), "the help's METHODS list lacks {method}");
        }
    }
}
