//! The `raytrail bench` flags, parsed and checked before any work starts.

use super::rays::RayKind;
use super::rays::RayOrder;
use super::view::ViewChoice;
use crate::flags::BUILTIN_SCENE;
use crate::flags::{LoadFlags, AUTO, BUILDERS};
use clap::Parser;
use raytrail::core::method::Method;
use raytrail::core::stream::{StreamParams, MAX_PACKET};
use raytrail::core::trace_order::TraceOrder;
use raytrail::gpu::{Dispatch, GpuConfig};
use raytrail::Builder;
use std::ffi::OsString;
use std::path::PathBuf;

/// Default primary image: 512 x 512 = 262,144 rays (shadow, diffuse and ambient-occlusion rays
/// follow from the primary hits). With the three scenes of BENCHMARKS.md (Sponza, the kitchen, the
/// full dragon), every target at 1 and 2 threads, the run took about five minutes on the project's
/// shared 2-core machine with the outside view alone (`--view outside`); the default `--view auto`
/// adds the inside views of Sponza and the kitchen.
pub const DEFAULT_SIZE: u32 = 512;

/// Default number of timed passes: the median of five rides out most of the shared machine's noise.
pub const DEFAULT_PASSES: usize = 5;

/// Default number of ambient-occlusion rays per primary hit.
pub const DEFAULT_AO_RAYS: usize = 4;

/// The peers a run can include, by command-line name (`embree` with the `embree` cargo feature).
#[cfg(not(feature = "embree"))]
pub const PEERS: &[&str] = &["obvhs-bvh2", "obvhs-cwbvh", "bvh"];
/// The peers a run can include, by command-line name (`embree` with the `embree` cargo feature).
#[cfg(feature = "embree")]
pub const PEERS: &[&str] = &["obvhs-bvh2", "obvhs-cwbvh", "bvh", "embree", "embree-high"];

/// What to measure, and where to write it.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// Scene files (or `builtin`), in order.
    pub scenes: Vec<PathBuf>,
    /// Ray types, in order.
    pub rays: Vec<RayKind>,
    /// Primary image width.
    pub width: u32,
    /// Primary image height.
    pub height: u32,
    /// Timed passes per measurement (after one warm-up pass).
    pub passes: usize,
    /// Thread counts to measure, ascending.
    pub threads: Vec<usize>,
    /// raytrail methods to measure.
    pub methods: Vec<Method>,
    /// Whether to measure `auto`: per batch, the method chosen by timing candidates on a sample.
    pub auto: bool,
    /// Peers to measure (names from [`PEERS`]).
    pub peers: Vec<String>,
    /// Target whose speed the ratio column divides by.
    pub baseline: String,
    /// Where to write JSON, if anywhere.
    pub json: Option<PathBuf>,
    /// Where to write the SVG plot, if anywhere.
    pub plot: Option<PathBuf>,
    /// Builder of raytrail's canonical tree.
    pub builder: Builder,
    /// Ambient-occlusion rays per primary hit.
    pub ao_rays: usize,
    /// Leave the GPU out even when wgpu finds an adapter.
    pub no_gpu: bool,
    /// Which camera views each scene is measured from.
    pub view: ViewChoice,
    /// The order of the rays ([`RayOrder`]).
    pub order: RayOrder,
    /// The trace orders each raytrail CPU method is measured in (`--trace-order`).
    pub trace_orders: Vec<TraceOrder>,
    /// Fail on mesh elements that are not triangles or polygons instead of skipping them.
    pub strict: bool,
    /// Parameter sets of the stream method: one target per set (the first is the default's).
    pub stream: Vec<StreamParams>,
    /// GPU settings: one GPU target per method and setting (the first is the default's).
    pub gpu: Vec<GpuConfig>,
    /// Untimed GPU tracing before a GPU target's kernel is timed.
    pub gpu_warm_up: std::time::Duration,
}

/// The `raytrail bench` flags as given; [`Options::from_args`] checks them.
#[derive(Parser, Debug, Clone)]
#[command(name = "bench")]
pub struct BenchArgs {
    /// Scene files (or `builtin`), comma-separated
    #[arg(long, short = 's', value_name = "FILE[,FILE...]", default_value = BUILTIN_SCENE)]
    pub scene: OsString,
    /// Ray types, comma-separated: primary, shadow, soft-shadow, diffuse, ao [default: all]
    #[arg(long, value_name = "TYPE[,TYPE...]")]
    pub rays: Option<String>,
    /// Primary image width
    #[arg(long, short = 'W', default_value_t = DEFAULT_SIZE)]
    pub width: u32,
    /// Primary image height
    #[arg(long, short = 'H', default_value_t = DEFAULT_SIZE)]
    pub height: u32,
    /// Timed passes per measurement, after one warm-up pass (the median is reported)
    #[arg(long, default_value_t = DEFAULT_PASSES)]
    pub passes: usize,
    /// Thread counts, comma-separated [default: 1 and all]
    #[arg(long, short = 'j', value_name = "N[,N...]")]
    pub threads: Option<String>,
    /// raytrail methods, comma-separated (auto: the method chosen per batch on a sample, as a
    /// target of its own), or all or none
    #[arg(long, value_name = "NAME,...|all|none", default_value = "all")]
    pub methods: String,
    /// Peers, comma-separated (obvhs-bvh2, obvhs-cwbvh, bvh; each also NAME+wt; embree with the
    /// `embree` feature), or all or none
    #[arg(long, value_name = "NAME,...|all|none", default_value = "all")]
    pub peers: String,
    /// Target the ratio column divides by [default: obvhs-bvh2, or the first method without peers]
    #[arg(long, value_name = "NAME")]
    pub baseline: Option<String>,
    /// Also write the results as JSON
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Also write an SVG plot of the results
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
    /// BVH2 builder of raytrail's tree: `best` builds with `sbvh` and `ploc` and keeps the lower SAH cost
    #[arg(long, default_value = "best", value_parser = BUILDERS)]
    pub builder: String,
    /// Ambient-occlusion rays per primary hit (1 to 64)
    #[arg(long, default_value_t = DEFAULT_AO_RAYS)]
    pub ao_rays: usize,
    /// Leave the GPU out even when wgpu finds an adapter
    #[arg(long)]
    pub no_gpu: bool,
    /// Stream method: most rays per packet (Garanzha & Loop's MaxSize), comma-separated for a
    /// parameter study [default: 256]
    #[arg(long, value_name = "N[,N...]")]
    pub stream_packet: Option<String>,
    /// Stream method: origin cell size as a fraction of the scene's diagonal (UserCellFraction),
    /// comma-separated for a parameter study [default: 0.004]
    #[arg(long, value_name = "F[,F...]")]
    pub stream_cell: Option<String>,
    /// GPU dispatch: auto (persistent threads for the wide stack methods, a grid for the rest),
    /// grid, persistent or persistent:<workgroups>, comma-separated for a sweep [default: auto]
    #[arg(long, value_name = "D[,D...]")]
    pub gpu_dispatch: Option<String>,
    /// GPU workgroup size, comma-separated for a sweep [default: 64]
    #[arg(long, value_name = "N[,N...]")]
    pub gpu_workgroup: Option<String>,
    /// Seconds of untimed GPU tracing before each GPU kernel is timed (clocks rise under load)
    #[arg(long, value_name = "SECONDS", default_value_t = 0.5)]
    pub gpu_warm_up: f64,
    /// Camera views: outside, inside, both, or auto (inside too where it sees a room)
    #[arg(long, default_value = ViewChoice::DEFAULT.name(), value_parser = ViewChoice::ALL.map(ViewChoice::name))]
    pub view: String,
    /// Ray order: morton (camera rays on a Z-curve, secondary rays after them), raster (camera
    /// rays row by row), shuffled (secondary rays in no order, as a path tracer's later bounces)
    #[arg(long, default_value = "morton", value_parser = RayOrder::ALL.map(RayOrder::name))]
    pub order: String,
    /// The order raytrail's CPU methods trace the rays in: given (as generated), sorted (each
    /// method sorts the batch by origin and octant first, its time included; the target is named
    /// METHOD/sorted) or both
    #[arg(long, default_value = "given", value_parser = ["given", "sorted", "both"])]
    pub trace_order: String,
    #[command(flatten)]
    pub load: LoadFlags,
}

impl Options {
    /// Parses and checks the flags after `raytrail bench` (as [`BenchArgs`] and
    /// [`Options::from_args`]); an error is a usage error.
    #[cfg(test)]
    pub fn parse(args: &[String]) -> Result<Options, String> {
        let a = BenchArgs::try_parse_from(std::iter::once("bench".to_string()).chain(args.iter().cloned()))
            .map_err(|e| e.to_string())?;
        Options::from_args(&a)
    }

    /// Checks the flags of `raytrail bench`; an error is a usage error.
    pub fn from_args(a: &BenchArgs) -> Result<Options, String> {
        let scenes = crate::args::path_list(&a.scene);
        if scenes.is_empty() {
            return Err("--scene: no scene given".to_string());
        }
        let rays = match a.rays.as_deref() {
            None => RayKind::ALL.to_vec(),
            Some(v) => unique(
                list(v)
                    .iter()
                    .map(|n| {
                        RayKind::from_name(n).ok_or_else(|| {
                            format!(
                                "--rays: unknown ray type '{n}' (known: {})",
                                RayKind::ALL.map(RayKind::name).join(", ")
                            )
                        })
                    })
                    .collect::<Result<_, _>>()?,
            ),
        };
        // `auto` is a target of its own (the method chosen per batch), not a method.
        let auto = a.methods != "all" && a.methods != "none" && list(&a.methods).iter().any(|n| n == AUTO);
        let methods = match a.methods.as_str() {
            "all" => Method::ALL.to_vec(),
            "none" => Vec::new(),
            v => unique(
                list(v)
                    .iter()
                    .filter(|n| *n != AUTO)
                    .map(|n| {
                        Method::from_name(n).ok_or_else(|| {
                            format!(
                                "--methods: unknown method '{n}' (known: {}, {AUTO})",
                                Method::ALL.map(Method::name).join(", ")
                            )
                        })
                    })
                    .collect::<Result<_, _>>()?,
            ),
        };
        let peers = match a.peers.as_str() {
            "all" => PEERS.iter().map(|p| p.to_string()).collect(),
            "none" => Vec::new(),
            v => {
                let given = unique(list(v));
                if let Some(bad) = given.iter().find(|p| !PEERS.contains(&p.as_str())) {
                    if crate::bench::peers::is_embree(bad) {
                        return Err(format!(
                            "--peers: '{bad}' is not available: this raytrail binary was built without the \
                             `embree` cargo feature (rebuild with `--features embree`, which links the system's \
                             libembree3)"
                        ));
                    }
                    return Err(format!("--peers: unknown peer '{bad}' (known: {}, all, none)", PEERS.join(", ")));
                }
                given
            }
        };
        if rays.is_empty() || (methods.is_empty() && !auto && peers.is_empty()) {
            return Err("nothing to measure: give at least one ray type and one method or peer".to_string());
        }
        let (width, height) = (a.width, a.height);
        if width == 0 || height == 0 || u64::from(width) * u64::from(height) > 1 << 26 {
            return Err(format!("--width/--height: {width} x {height} must be at least 1 x 1 and at most 2^26 pixels"));
        }
        let passes = a.passes;
        if passes == 0 {
            return Err("--passes must be at least 1".to_string());
        }
        let ao_rays = a.ao_rays;
        if ao_rays == 0 || ao_rays > 64 {
            return Err("--ao-rays must be between 1 and 64".to_string());
        }
        let all = std::thread::available_parallelism().map_or(1, |n| n.get());
        let threads = match a.threads.as_deref() {
            None => unique(vec![1, all]),
            Some(v) => {
                let mut t: Vec<usize> = list(v)
                    .iter()
                    .map(|n| match n.parse::<usize>() {
                        Ok(k) if (1..=1024).contains(&k) => Ok(k),
                        _ => Err(format!("--threads: '{n}' is not a thread count between 1 and 1024")),
                    })
                    .collect::<Result<_, _>>()?;
                t.sort_unstable();
                t.dedup();
                t
            }
        };
        if threads.is_empty() {
            return Err("--threads: no thread count given".to_string());
        }
        // Without peers, the default baseline is the first method run.
        let baseline = match (a.baseline.as_deref(), methods.first()) {
            (Some(b), _) => b.to_string(),
            (None, Some(first)) if peers.is_empty() => first.name().to_string(),
            (None, None) if peers.is_empty() => AUTO.to_string(),
            (None, _) => "obvhs-bvh2".to_string(),
        };
        let stream = stream_params(a.stream_packet.as_deref(), a.stream_cell.as_deref())?;
        let gpu = gpu_configs(a.gpu_dispatch.as_deref(), a.gpu_workgroup.as_deref())?;
        if !(a.gpu_warm_up.is_finite() && (0.0..=600.0).contains(&a.gpu_warm_up)) {
            return Err(format!("--gpu-warm-up: {} is not a number of seconds from 0 to 600", a.gpu_warm_up));
        }
        Ok(Options {
            gpu,
            gpu_warm_up: std::time::Duration::from_secs_f64(a.gpu_warm_up),
            auto,
            stream,
            scenes,
            rays,
            width,
            height,
            passes,
            threads,
            methods,
            peers,
            baseline,
            json: a.json.clone(),
            plot: a.plot.clone(),
            builder: Builder::from_name(&a.builder).ok_or_else(|| {
                let known: Vec<&str> = Builder::ALL.iter().map(|b| b.name()).collect();
                format!("unknown builder '{}' (known: {})", a.builder, known.join(", "))
            })?,
            ao_rays,
            no_gpu: a.no_gpu,
            view: ViewChoice::from_name(&a.view)?,
            order: RayOrder::from_name(&a.order).ok_or_else(|| format!("--order: unknown order '{}'", a.order))?,
            trace_orders: match a.trace_order.as_str() {
                "sorted" => vec![TraceOrder::Sorted],
                "both" => vec![TraceOrder::AsGiven, TraceOrder::Sorted],
                _ => vec![TraceOrder::AsGiven],
            },
            strict: a.load.strict,
        })
    }
}

/// Every combination of the given packet sizes and cell fractions (defaults where not given).
fn stream_params(packets: Option<&str>, cells: Option<&str>) -> Result<Vec<StreamParams>, String> {
    let base = StreamParams::default();
    let packets: Vec<u32> = match packets {
        None => vec![base.max_packet],
        Some(v) => list(v)
            .iter()
            .map(|n| match n.parse::<u32>() {
                Ok(k) if (1..=MAX_PACKET).contains(&k) => Ok(k),
                _ => Err(format!("--stream-packet: '{n}' is not a packet size between 1 and {MAX_PACKET}")),
            })
            .collect::<Result<_, _>>()?,
    };
    let cells: Vec<f32> = match cells {
        None => vec![base.origin_cell_fraction],
        Some(v) => list(v)
            .iter()
            .map(|n| match n.parse::<f32>() {
                Ok(f) if f.is_finite() && f > 0.0 && f <= 1.0 => Ok(f),
                _ => Err(format!("--stream-cell: '{n}' is not a fraction in (0, 1]")),
            })
            .collect::<Result<_, _>>()?,
    };
    if packets.is_empty() || cells.is_empty() {
        return Err("--stream-packet/--stream-cell: no value given".to_string());
    }
    Ok(unique(
        packets
            .iter()
            .flat_map(|&max_packet| {
                cells.iter().map(move |&origin_cell_fraction| StreamParams { max_packet, origin_cell_fraction, ..base })
            })
            .collect(),
    ))
}

/// Every combination of the given GPU dispatches and workgroup sizes (defaults where not given).
fn gpu_configs(dispatches: Option<&str>, workgroups: Option<&str>) -> Result<Vec<GpuConfig>, String> {
    let base = GpuConfig::default();
    let dispatches: Vec<Dispatch> = match dispatches {
        None => vec![base.dispatch],
        Some(v) => list(v)
            .iter()
            .map(|d| Dispatch::parse(d).map_err(|e| format!("--gpu-dispatch: {e}")))
            .collect::<Result<_, _>>()?,
    };
    let sizes: Vec<u32> = match workgroups {
        None => vec![base.workgroup_size],
        Some(v) => list(v)
            .iter()
            .map(|n| match n.parse::<u32>() {
                Ok(k) if (1..=1024).contains(&k) => Ok(k),
                _ => Err(format!("--gpu-workgroup: '{n}' is not a workgroup size between 1 and 1024")),
            })
            .collect::<Result<_, _>>()?,
    };
    if dispatches.is_empty() || sizes.is_empty() {
        return Err("--gpu-dispatch/--gpu-workgroup: no value given".to_string());
    }
    let mut out: Vec<GpuConfig> = Vec::new();
    for &dispatch in &dispatches {
        for &workgroup_size in &sizes {
            let c = GpuConfig { dispatch, workgroup_size, ..base };
            if !out.contains(&c) {
                out.push(c);
            }
        }
    }
    Ok(out)
}

/// The non-empty items of a comma-separated list, trimmed.
fn list(v: &str) -> Vec<String> {
    v.split(',').map(str::trim).filter(|s| !s.is_empty()).map(str::to_string).collect()
}

/// `items` without repeats, first occurrence kept.
fn unique<T: PartialEq>(items: Vec<T>) -> Vec<T> {
    let mut out: Vec<T> = Vec::with_capacity(items.len());
    for i in items {
        if !out.contains(&i) {
            out.push(i);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use raytrail::core::method::Bvh2Method;

    fn parse(s: &str) -> Result<Options, String> {
        Options::parse(&s.split_whitespace().map(str::to_string).collect::<Vec<_>>())
    }

    #[test]
    fn auto_is_a_target_of_its_own() {
        assert!(!parse("").unwrap().auto, "`all` is the fixed methods");
        let o = parse("--methods stack,auto,bvh8 --peers none").unwrap();
        assert!(o.auto);
        assert_eq!(o.methods, vec![Method::from_name("stack").unwrap(), Method::from_name("bvh8").unwrap()]);
        assert_eq!(o.baseline, "stack");
        let o = parse("--methods auto --peers none").unwrap();
        assert!(o.auto && o.methods.is_empty());
        assert_eq!(o.baseline, "auto");
        assert_eq!(parse("--peers none").unwrap().trace_orders, vec![TraceOrder::AsGiven]);
        let o = parse("--trace-order both --peers none").unwrap();
        assert_eq!(o.trace_orders, vec![TraceOrder::AsGiven, TraceOrder::Sorted]);
        assert!(parse("--trace-order backwards").is_err());
        let e = parse("--methods automatic").unwrap_err();
        assert!(e.contains("unknown method 'automatic'") && e.contains(", auto)"), "{e}");
    }

    #[test]
    fn defaults_and_lists() {
        let o = parse("").unwrap();
        assert_eq!(o.scenes, vec![PathBuf::from("builtin")]);
        assert_eq!(o.rays, RayKind::ALL.to_vec());
        assert_eq!(o.methods, Method::ALL.to_vec());
        assert_eq!(o.baseline, "obvhs-bvh2");
        assert_eq!(o.threads[0], 1);
        assert_eq!(o.view, ViewChoice::DEFAULT);
        assert!(!o.strict && parse("--strict").unwrap().strict);
        assert_eq!(parse("--view both").unwrap().view, ViewChoice::Both);
        assert_eq!(o.order, RayOrder::Morton);
        assert_eq!(parse("--order shuffled").unwrap().order, RayOrder::Shuffled);
        let e = parse("--scene a.obj --colour red").unwrap_err();
        assert!(e.contains("unexpected argument '--colour'"), "{e}");
        let o = parse("--scene a.obj,,b.ply --rays ao,primary,ao --threads 2,1,2 --methods hash,stack").unwrap();
        assert_eq!(o.scenes, vec![PathBuf::from("a.obj"), PathBuf::from("b.ply")]);
        assert_eq!(o.rays, vec![RayKind::Ao, RayKind::Primary]);
        assert_eq!(o.threads, vec![1, 2]);
        assert_eq!(o.methods, vec![Bvh2Method::Hash.into(), Bvh2Method::Stack.into()]);
        assert_eq!(o.baseline, "obvhs-bvh2", "peers run by default: the baseline is obvhs-bvh2");
        assert_eq!(
            parse("--peers none --methods uncle,stack").unwrap().baseline,
            "uncle",
            "no peers: the first method"
        );
        assert_eq!(parse("--peers none --baseline stack").unwrap().baseline, "stack");
    }

    #[test]
    fn bad_values_are_errors() {
        for bad in [
            "--rays sideways",
            "--methods fastest",
            "--peers bvh,fastest",
            "--view above",
            "--order sorted",
            "--threads 0",
            "--passes 0",
            "--width 0",
            "--builder fastest",
            "--methods none --peers none",
            "--ao-rays 0",
        ] {
            assert!(parse(bad).is_err(), "{bad} was accepted");
        }
    }

    #[cfg(not(feature = "embree"))]
    #[test]
    fn embree_needs_the_feature() {
        let e = parse("--peers obvhs-bvh2,embree").unwrap_err();
        assert!(e.contains("built without the `embree` cargo feature"), "{e}");
        assert!(!parse("--peers all").unwrap().peers.contains(&"embree".to_string()));
    }

    #[cfg(feature = "embree")]
    #[test]
    fn embree_is_a_peer_with_the_feature() {
        assert_eq!(parse("--peers embree").unwrap().peers, vec!["embree"]);
        assert!(parse("--peers all").unwrap().peers.contains(&"embree".to_string()));
        assert!(parse("--peers embree --baseline embree").is_ok());
        assert!(parse("--peers all").unwrap().peers.contains(&"embree-high".to_string()));
    }
}
