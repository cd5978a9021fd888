//! Scene analysis: what a scene, and the rays traced through it, need of raytrail, so that it
//! pays only for that ([`analyze`], shown by `raytrail explain`).
//!
//! - [`choice`]: picking a method per kind of ray from timings of a sample (`--method auto`);
//! - [`sample`]: the sample and the CPU backend's clock;
//! - [`plans`]: the choices a [`Tracer`](crate::Tracer) keeps per kind of batch;
//! - [`needs`]: whether 64-bit keys, hash tables, the `f64` fallback, the disjoint mask and the
//!   slack are needed;
//! - `shaders` (feature `gpu`): the wgpu kernels the choices compile.
//!
//! The tables each method builds, and their sizes, come from the core's
//! `Part` ([`raytrail_core::prepared::Part`]).

pub mod choice;
pub mod needs;
pub mod order;
pub mod plans;
pub mod sample;
#[cfg(feature = "gpu")]
pub mod shaders;
pub mod streams;

use choice::Choice;
use needs::Needs;
use raytrail_core::bvh2::Bvh2;
use raytrail_core::key::KeyWidth;
use raytrail_core::method::{Bvh2Method, KdMethod, Method, Query, StreamMethod, WideMethod};
use raytrail_core::prepared::{Part, PreparedScene};
use raytrail_core::scene::Scene;
use raytrail_core::trace::{Trace, TraceOptions};
use raytrail_core::{Error, Hit, Ray};
use raytrail_cpu::{CpuBackend, CpuScene};
use std::sync::Arc;

/// A batch of rays of one kind, to choose a method for.
#[derive(Clone, Debug)]
pub struct RaySet {
    /// What the rays are ("primary", "shadow", a file name, ...).
    pub label: String,
    /// Closest or any hit.
    pub query: Query,
    /// The rays.
    pub rays: Vec<Ray>,
}

/// One part's size and the time it took to build, alone.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PartFigure {
    /// The part.
    pub part: Part,
    /// Its bytes.
    pub bytes: usize,
    /// Seconds to build it from the canonical tree (the layouts: both, alone each).
    pub seconds: f64,
}

/// The choice for one ray set.
#[derive(Clone, Debug, PartialEq)]
pub struct SetChoice {
    /// The set's label.
    pub label: String,
    /// Its query.
    pub query: Query,
    /// Rays in the set.
    pub rays: usize,
    /// Rays in the sample the candidates were timed on.
    pub sample: usize,
    /// What was chosen, and the timings.
    pub choice: Choice,
    /// Seconds of one trace of the whole set with the chosen method (what the choosing costs
    /// is measured against).
    pub batch_seconds: f64,
    /// Rays of the set refused by every method (outside the supported numeric range).
    pub refused: usize,
}

/// What [`analyze`] finds.
#[derive(Clone, Debug)]
pub struct SceneAnalysis {
    /// Triangles in the scene.
    pub triangles: usize,
    /// Depth of the canonical tree.
    pub depth: u32,
    /// Key width the depth needs ([`KeyWidth::for_depth`]).
    pub key_width: KeyWidth,
    /// Bytes of the canonical tree every scene keeps.
    pub tree_bytes: usize,
    /// Every part, built alone.
    pub parts: Vec<PartFigure>,
    /// The choice per ray set, in the order given.
    pub choices: Vec<SetChoice>,
    /// The decisions for the chosen methods.
    pub needs: Needs,
}

impl SceneAnalysis {
    /// The distinct chosen methods, in the order first chosen.
    pub fn chosen(&self) -> Vec<Method> {
        let mut out: Vec<Method> = Vec::new();
        for c in &self.choices {
            if !out.contains(&c.choice.method) {
                out.push(c.choice.method);
            }
        }
        out
    }

    /// The figures of one part.
    pub fn part(&self, part: Part) -> Option<&PartFigure> {
        self.parts.iter().find(|p| p.part == part)
    }

    /// Bytes of the tables `method` builds (the canonical tree not included).
    pub fn method_bytes(&self, method: Method) -> usize {
        Part::of(method).iter().filter_map(|&p| self.part(p)).map(|p| p.bytes).sum()
    }

    /// Bytes and build seconds of the parts `methods` read together (each part once).
    pub fn cost_of(&self, methods: &[Method]) -> (usize, f64) {
        self.parts.iter().filter(|p| p.part.needed_by(methods)).fold((0, 0.0), |(b, s), p| (b + p.bytes, s + p.seconds))
    }

    /// The wgpu kernels the choices compile.
    #[cfg(feature = "gpu")]
    pub fn variants(&self) -> Vec<raytrail_wgpu::compose::Variant> {
        let chosen: Vec<(Method, Query)> = self.choices.iter().map(|c| (c.choice.method, c.query)).collect();
        shaders::variants_for(self.key_width, &chosen)
    }
}

/// The method that makes `part` (and nothing but it and the layout the hash tables are built
/// over) when [`PreparedScene::new`] is given it alone.
pub fn maker(part: Part) -> Method {
    match part {
        Part::UncleLayout => Method::Bvh2(Bvh2Method::Stack),
        Part::ParentLayout => Method::Bvh2(Bvh2Method::ParentSibling),
        Part::Hash => Method::Bvh2(Bvh2Method::Hash),
        Part::FullHash => Method::Bvh2(Bvh2Method::HashResume),
        Part::Kd => Method::Kd(KdMethod::Stack),
        Part::Wide4 => Method::Wide(WideMethod::BVH4),
        Part::Wide4Hash => Method::Wide(WideMethod::BVH4_HASH),
        Part::Wide8 => Method::Wide(WideMethod::BVH8),
        Part::Wide4Naive => Method::Wide(WideMethod::BVH4_NAIVE),
        Part::Wide8Sah => Method::Wide(WideMethod::BVH8_SAH),
        Part::Levels => Method::Stream(StreamMethod::Frustum8),
    }
}

/// Builds every part of `scene` over `bvh`, each alone so its time is its own, and returns them
/// together in one prepared scene (every method can trace it) with each part's figures.
/// `progress` is told each part as it starts.
pub fn prepare_every_part(
    scene: &Scene,
    bvh: &Bvh2,
    progress: &mut dyn FnMut(&str),
) -> Result<(PreparedScene, Vec<PartFigure>), Error> {
    let mut all: Option<PreparedScene> = None;
    let mut figures = Vec::new();
    for part in Part::ALL {
        progress(part.name());
        let mut p = PreparedScene::new(scene, bvh.clone(), &[maker(part)])?;
        let t = p.timings;
        let seconds = match part {
            Part::UncleLayout | Part::ParentLayout => t.layouts,
            Part::Hash => t.hash,
            Part::FullHash => t.full_hash,
            Part::Kd => t.kd,
            Part::Wide4 | Part::Wide8 | Part::Wide4Naive | Part::Wide8Sah => t.wide,
            Part::Wide4Hash => t.wide_hash,
            Part::Levels => t.levels,
        };
        let bytes = p.part_bytes(part).ok_or(Error::NotPrepared { method: maker(part).name(), missing: "its part" })?;
        figures.push(PartFigure { part, bytes, seconds });
        let Some(acc) = all.as_mut() else {
            all = Some(p);
            continue;
        };
        match part {
            Part::UncleLayout => acc.uncles = p.uncles.take(),
            Part::ParentLayout => acc.parents = p.parents.take(),
            Part::Hash => acc.hash = p.hash.take(),
            Part::FullHash => acc.full_hash = p.full_hash.take(),
            Part::Kd => acc.kd = p.kd.take(),
            Part::Wide4 => acc.wide4 = p.wide4.take(),
            Part::Wide4Hash => acc.wide4_hash = p.wide4_hash.take(),
            Part::Wide8 => acc.wide8 = p.wide8.take(),
            Part::Wide4Naive => acc.wide4_naive = p.wide4_naive.take(),
            Part::Wide8Sah => acc.wide8_sah = p.wide8_sah.take(),
            Part::Levels => acc.levels = p.levels.take(),
        }
    }
    let all = all.ok_or(Error::EmptyScene)?;
    Ok((all, figures))
}

/// Analyzes `scene` with its canonical tree `bvh`: builds every part alone (sizes and times),
/// chooses a method for each of `sets` by timing [`choice::CANDIDATES`] on a sample
/// ([`sample::choose_on_cpu`]) and traces each set once with its choice (to weigh the sample's
/// cost), and decides the [`Needs`] of the chosen methods. `progress` is told each step.
pub fn analyze(
    scene: &Scene,
    bvh: &Bvh2,
    sets: &[RaySet],
    backend: &CpuBackend,
    progress: &mut dyn FnMut(&str),
) -> Result<SceneAnalysis, Error> {
    let stats = bvh.stats();
    let tree_bytes = std::mem::size_of_val(bvh.nodes()) + std::mem::size_of_val(bvh.prim_order());
    let (prepared, parts) = prepare_every_part(scene, bvh, progress)?;
    let prepared = Arc::new(prepared);
    let cpu = backend.prepare(prepared.clone())?;
    let mut choices = Vec::with_capacity(sets.len());
    let mut refused_total = (0, 0);
    for set in sets {
        progress(&format!("choosing for {}", set.label));
        let choice = sample::choose_on_cpu(backend, &cpu, &set.rays, set.query)?;
        let mut hits = vec![Hit::MISS; set.rays.len()];
        let report = backend.trace(&cpu, &set.rays, &TraceOptions::new(choice.method).query(set.query), &mut hits)?;
        let refused = needs::refused_rays(&prepared, &set.rays);
        refused_total = (refused_total.0 + refused, refused_total.1 + set.rays.len());
        choices.push(SetChoice {
            label: set.label.clone(),
            query: set.query,
            rays: set.rays.len(),
            sample: sample::sample_size(set.rays.len()),
            choice,
            batch_seconds: report.seconds,
            refused,
        });
    }
    let mut analysis = SceneAnalysis {
        triangles: scene.triangles().len(),
        depth: stats.depth,
        key_width: stats.key_width,
        tree_bytes,
        parts,
        choices,
        needs: Needs::decide(scene, stats.depth, &[], None),
    };
    let given = (!sets.is_empty()).then_some(refused_total);
    analysis.needs = Needs::decide(scene, stats.depth, &analysis.chosen(), given);
    Ok(analysis)
}

/// Prepares `scene` for `auto`: the candidates' parts, so that [`choose_and_keep`] can time them.
pub fn prepare_candidates(scene: &Scene, bvh: Bvh2) -> Result<PreparedScene, Error> {
    PreparedScene::new(scene, bvh, &choice::CANDIDATES)
}

/// Chooses a method for `rays` on `prepared` (made by [`prepare_candidates`]), then drops the
/// parts the chosen method does not read, so that only its tables stay in memory. Returns the
/// prepared scene to trace and the choice.
pub fn choose_and_keep(
    backend: &CpuBackend,
    prepared: PreparedScene,
    rays: &[Ray],
    query: Query,
) -> Result<(PreparedScene, Choice), Error> {
    let scene = CpuScene(Arc::new(prepared));
    let choice = sample::choose_on_cpu(backend, &scene, rays, query)?;
    let mut prepared = Arc::try_unwrap(scene.0).unwrap_or_else(|shared| (*shared).clone());
    prepared.retain_parts_for(&[choice.method]);
    Ok((prepared, choice))
}

#[cfg(test)]
mod tests {
    use super::*;
    use raytrail_conformance::rays::{default_light, primary, scene_epsilon, shadow};

    fn sphereflake() -> Scene {
        raytrail_conformance::generated().into_iter().find(|s| s.name == "sphereflake").unwrap().scene
    }

    #[test]
    fn every_part_built_alone_adds_up_to_a_scene_every_method_traces() {
        let scene = sphereflake();
        let bvh = raytrail_core::bvh2::SahBuilder::default().build(scene.triangles()).unwrap();
        let mut told = Vec::new();
        let (all, figures) = prepare_every_part(&scene, &bvh, &mut |s| told.push(s.to_string())).unwrap();
        assert_eq!(figures.len(), Part::ALL.len());
        assert_eq!(told.len(), Part::ALL.len());
        for m in Method::ALL {
            assert!(all.check_prepared(m).is_ok(), "{m}");
        }
        for f in &figures {
            assert_eq!(all.part_bytes(f.part), Some(f.bytes), "{}", f.part);
        }
    }

    #[test]
    fn analysis_of_the_builtin_scene() {
        let scene = sphereflake();
        let bvh = raytrail_core::bvh2::SahBuilder::default().build(scene.triangles()).unwrap();
        let prim = primary(&scene, 32, 24);
        let backend = CpuBackend::new();
        let mut hits = vec![Hit::MISS; prim.len()];
        let p = Arc::new(PreparedScene::new(&scene, bvh.clone(), &[Method::Bvh2(Bvh2Method::Stack)]).unwrap());
        let cpu = backend.prepare(p).unwrap();
        backend.trace(&cpu, &prim, &TraceOptions::new(Method::Bvh2(Bvh2Method::Stack)), &mut hits).unwrap();
        let b = scene.bounds();
        let sh = shadow(&prim, &hits, default_light(b), scene_epsilon(b));
        let sets = [
            RaySet { label: "primary".into(), query: Query::Closest, rays: prim },
            RaySet { label: "shadow".into(), query: Query::Any, rays: sh },
        ];
        let a = analyze(&scene, &bvh, &sets, &backend, &mut |_| {}).unwrap();
        assert_eq!(a.choices.len(), 2);
        for c in &a.choices {
            assert!(choice::CANDIDATES.contains(&c.choice.method));
            assert!(c.choice.cost_seconds > 0.0 && c.batch_seconds > 0.0);
        }
        let chosen = a.chosen();
        let (chosen_bytes, _) = a.cost_of(&chosen);
        let (all_bytes, _) = a.cost_of(&Method::ALL);
        assert!(chosen_bytes < all_bytes);
        assert_eq!(a.needs.hash_tables.needed, chosen.iter().any(|m| m.needs_hash()));
        #[cfg(feature = "gpu")]
        assert!(!a.variants().is_empty() && a.variants().len() <= 2);
        // No rays: nothing chosen, nothing compiled.
        let none = analyze(&scene, &bvh, &[], &backend, &mut |_| {}).unwrap();
        assert!(none.choices.is_empty());
        #[cfg(feature = "gpu")]
        assert!(none.variants().is_empty());
    }

    #[test]
    fn choosing_keeps_only_the_chosen_methods_tables() {
        let scene = sphereflake();
        let bvh = raytrail_core::bvh2::SahBuilder::default().build(scene.triangles()).unwrap();
        let prepared = prepare_candidates(&scene, bvh.clone()).unwrap();
        let rays = primary(&scene, 16, 16);
        let (kept, choice) = choose_and_keep(&CpuBackend::new(), prepared, &rays, Query::Closest).unwrap();
        assert!(kept.check_prepared(choice.method).is_ok());
        for part in Part::ALL {
            assert_eq!(kept.part_bytes(part).is_some(), Part::of(choice.method).contains(&part), "{part}");
        }
        // An empty batch is an error, not a panic.
        let prepared = prepare_candidates(&scene, bvh).unwrap();
        assert!(choose_and_keep(&CpuBackend::new(), prepared, &[], Query::Closest).is_err());
    }
}
