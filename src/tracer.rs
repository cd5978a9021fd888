//! [`Tracer`]: a triangle scene ready to trace in one call, with the defaults that suit most rays.
//!
//! The tracer owns its tree, so a tree cannot meet the wrong scene. It builds the canonical BVH2
//! with [`Builder::Best`], collapses it into the 8-wide tree of least node area (Ylitie, Karras &
//! Laine 2017) and keeps nothing else: every walk it picks from reads that one tree. For a large
//! batch it chooses among the three walks as `--method auto` does (single rays and packets timed
//! on a sample of the rays, the ray lists on whole streams of the batch: `analysis::streams`),
//! and traces the batch with the fastest, keeping the choice for the next calls with a batch of
//! that kind (`analysis::plans`); a small batch goes ray by ray (what suits rays in no useful
//! order). A method named with [`TracerBuilder::method`] is used for every batch instead, and the
//! scene is prepared for it alone.

use crate::analysis::plans::{BatchKind, Plans};
use crate::analysis::sample::choose_among;
use crate::{Builder, Error, InstancedTracer};
use raytrail_core::all_hits::{AllHits, AllHitsOptions};
use raytrail_core::instance::Instance;
use raytrail_core::method::{Method, Query, WideMethod};
use raytrail_core::nearest::NearestPoint;
use raytrail_core::prepared::PreparedScene;
use raytrail_core::scene::{Mesh, Scene};
use raytrail_core::trace::{Report, Trace, TraceOptions};
use raytrail_core::trace_order::TraceOrder;
use raytrail_core::{Hit, Ray};
use raytrail_cpu::{CpuBackend, CpuScene};
use std::cell::RefCell;
use std::sync::{Arc, Mutex, PoisonError};

/// The walks of the 8-wide tree of least node area that the default tracer picks from: single
/// rays (incoherent rays, small batches), packets (camera rays, shadow rays toward one light),
/// streams (incoherent closest-hit rays in large batches).
pub const AUTO_WALKS: [Method; 3] = [
    Method::Wide(WideMethod::BVH8_SAH),
    Method::Wide(WideMethod::BVH8_SAH_PACKET),
    Method::Wide(WideMethod::BVH8_SAH_LISTS),
];

/// Batches of fewer rays are traced with the first of [`AUTO_WALKS`] without timing the others:
/// a sample of at least 512 rays ([`crate::analysis::sample::sample_size`]), timed about ten times, would cost more than a
/// third of such a batch.
pub const AUTO_MIN_RAYS: usize = 1 << 16;

/// How a [`Tracer`] is made: the tree builder, the method, the threads and what to do with rays
/// that cannot hit anything. Start from [`Tracer::builder`].
#[derive(Clone, Copy, Debug, Default)]
pub struct TracerBuilder {
    pub(crate) tree: Builder,
    pub(crate) method: Option<Method>,
    threads: Option<usize>,
    pub(crate) reject_untraceable: bool,
}

impl TracerBuilder {
    /// The builder of the canonical tree ([`Builder::Best`] unless set).
    pub fn tree_builder(mut self, builder: Builder) -> Self {
        self.tree = builder;
        self
    }

    /// Traces every batch with `method` (any of [`Method::ALL`]), preparing the scene for it
    /// alone, instead of picking among [`AUTO_WALKS`].
    pub fn method(mut self, method: impl Into<Method>) -> Self {
        self.method = Some(method.into());
        self
    }

    /// Traces on a pool of its own of `threads` threads instead of rayon's global pool.
    pub fn threads(mut self, threads: usize) -> Self {
        self.threads = Some(threads);
        self
    }

    /// Whether a batch holding a ray that cannot hit anything (a NaN or infinite component, a zero
    /// direction, a NaN bound or `tmin > tmax`) fails with [`Error::UntraceableRays`] before any
    /// ray is traced. Off by default: such rays are misses, counted in
    /// [`Report::untraceable`].
    pub fn reject_untraceable(mut self, reject: bool) -> Self {
        self.reject_untraceable = reject;
        self
    }

    /// A tracer over an indexed mesh held in arrays: `vertices` by position, `triangles` by the
    /// indices of their vertices; primitive ids are indices into `triangles`.
    pub fn build(self, vertices: &[[f32; 3]], triangles: &[[u32; 3]]) -> Result<Tracer, Error> {
        self.build_scene(&Scene::from_indexed(vertices, triangles)?)
    }

    /// A tracer over a loaded mesh ([`crate::load`]).
    pub fn build_mesh(self, mesh: &Mesh) -> Result<Tracer, Error> {
        self.build_scene(&mesh.to_scene()?)
    }

    /// A tracer over `instances` of `meshes` (an [`Instance`]'s `mesh` indexes `meshes`), each
    /// mesh's tree built once by this builder's tree builder, every instance traced with its
    /// method ([`INSTANCED_DEFAULT`](crate::INSTANCED_DEFAULT) unless named; `auto` does not
    /// apply). Errors name the instance whose mesh index is out of range or whose transform
    /// cannot be inverted.
    pub fn build_instanced(self, meshes: &[Scene], instances: &[Instance]) -> Result<InstancedTracer, Error> {
        InstancedTracer::build(self, meshes, instances)
    }

    /// The backend on this builder's threads.
    pub(crate) fn backend(&self) -> Result<CpuBackend, Error> {
        Ok(match self.threads {
            Some(n) => CpuBackend::with_threads(n).map_err(Error::ThreadPool)?,
            None => CpuBackend::new(),
        })
    }

    /// A tracer over a validated scene.
    pub fn build_scene(self, scene: &Scene) -> Result<Tracer, Error> {
        let backend = self.backend()?;
        let bvh = self.tree.build(scene)?;
        let methods: &[Method] = match &self.method {
            Some(m) => std::slice::from_ref(m),
            None => &AUTO_WALKS,
        };
        let prepared = backend.prepare(Arc::new(PreparedScene::new(scene, bvh, methods)?))?;
        Ok(Tracer {
            backend,
            scene: prepared,
            method: self.method,
            reject_untraceable: self.reject_untraceable,
            plans: Mutex::default(),
        })
    }
}

/// A triangle scene ready to trace on the CPU: closest hits ([`Tracer::intersect`]) and
/// occlusion ([`Tracer::occluded`]) of batches or single rays.
///
/// ```
/// use raytrail::{Ray, Tracer, Vec3};
/// # fn main() -> Result<(), raytrail::Error> {
/// let tracer = Tracer::new(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], &[[0, 1, 2]])?;
/// let hit = tracer.intersect_one(&Ray::new(Vec3::new(0.25, 0.25, 1.0), -Vec3::Z, 0.0, f32::INFINITY))?;
/// assert_eq!(hit.map(|h| (h.prim, h.t)), Some((0, 1.0)));
/// # Ok(())
/// # }
/// ```
///
/// Hits are bit for bit those of every other method and backend (the conformance suite's
/// contract): `t`, the primitive id (index of the triangle) and the barycentrics `u`, `v` of the
/// second and third vertex.
#[derive(Debug)]
pub struct Tracer {
    backend: CpuBackend,
    scene: CpuScene,
    method: Option<Method>,
    reject_untraceable: bool,
    /// `auto`'s choices by kind of batch, each reused for a number of calls
    /// ([`crate::analysis::plans`]).
    plans: Mutex<Plans<(Method, TraceOrder)>>,
}

thread_local! {
    /// Hit slots for the occlusion calls, which answer with booleans: kept per thread and grown to
    /// the largest batch seen, so that a renderer's repeated calls allocate once.
    static SCRATCH: RefCell<Vec<Hit>> = const { RefCell::new(Vec::new()) };
}

impl Tracer {
    /// A tracer with the defaults over an indexed mesh held in arrays (see
    /// [`TracerBuilder::build`]).
    pub fn new(vertices: &[[f32; 3]], triangles: &[[u32; 3]]) -> Result<Tracer, Error> {
        TracerBuilder::default().build(vertices, triangles)
    }

    /// A tracer with the defaults over a loaded mesh ([`crate::load`]).
    pub fn from_mesh(mesh: &Mesh) -> Result<Tracer, Error> {
        TracerBuilder::default().build_mesh(mesh)
    }

    /// The builder of a tracer with other than the defaults.
    pub fn builder() -> TracerBuilder {
        TracerBuilder::default()
    }

    /// The prepared scene (the tree and the tables its methods read), for the expert API.
    pub fn prepared(&self) -> &Arc<PreparedScene> {
        &self.scene.0
    }

    /// Triangles in the scene.
    pub fn triangle_count(&self) -> usize {
        self.scene.0.bvh.prim_count()
    }

    /// The closest hit of each ray ([`Hit::MISS`] where there is none).
    pub fn intersect(&self, rays: &[Ray]) -> Result<Vec<Hit>, Error> {
        let mut hits = vec![Hit::MISS; rays.len()];
        self.intersect_into(rays, &mut hits)?;
        Ok(hits)
    }

    /// The closest hit of each ray into `hits` (one slot per ray), allocating nothing but a large
    /// batch's timing sample; the report counts the untraceable and refused rays.
    pub fn intersect_into(&self, rays: &[Ray], hits: &mut [Hit]) -> Result<Report, Error> {
        self.trace(rays, Query::Closest, hits)
    }

    /// The closest hit of one ray, `None` for a miss (and for a ray that cannot hit anything,
    /// unless the tracer rejects those).
    pub fn intersect_one(&self, ray: &Ray) -> Result<Option<Hit>, Error> {
        let mut hit = [Hit::MISS];
        self.trace(std::slice::from_ref(ray), Query::Closest, &mut hit)?;
        one(hit[0])
    }

    /// Whether anything blocks each ray within its interval.
    pub fn occluded(&self, rays: &[Ray]) -> Result<Vec<bool>, Error> {
        let mut out = vec![false; rays.len()];
        self.occluded_into(rays, &mut out)?;
        Ok(out)
    }

    /// Whether anything blocks each ray, into `out` (one slot per ray). The hit slots the
    /// backend writes are kept per thread, so repeated calls allocate only when a batch is larger
    /// than any before it on the thread.
    pub fn occluded_into(&self, rays: &[Ray], out: &mut [bool]) -> Result<Report, Error> {
        if rays.len() != out.len() {
            return Err(raytrail_core::Error::BufferMismatch { rays: rays.len(), hits: out.len() }.into());
        }
        SCRATCH.with(|scratch| {
            let mut hits = scratch.borrow_mut();
            if hits.len() < rays.len() {
                hits.resize(rays.len(), Hit::MISS);
            }
            let hits = &mut hits[..rays.len()];
            let report = self.trace(rays, Query::Any, hits)?;
            for (o, h) in out.iter_mut().zip(hits.iter()) {
                *o = h.is_hit();
            }
            Ok(report)
        })
    }

    /// Whether anything blocks one ray within its interval.
    pub fn occluded_one(&self, ray: &Ray) -> Result<bool, Error> {
        let mut hit = [Hit::MISS];
        self.trace(std::slice::from_ref(ray), Query::Any, &mut hit)?;
        Ok(one(hit[0])?.is_some())
    }

    /// Every hit of each ray within its interval, in order of `t` (ties by primitive id), each
    /// triangle at most once, as `options` keep them: at most [`AllHitsOptions::max_hits`] per
    /// ray (the nearest, the list marked truncated), and hits at one `t` merged where asked. A
    /// ray through an edge two triangles share gets both triangles, once each, at one `t`. Each
    /// hit is bit for bit the closest hit the ray would have if the triangle were alone in the
    /// scene, so a list's first hit is [`Tracer::intersect`]'s.
    ///
    /// ```
    /// use raytrail::{AllHitsOptions, Ray, Tracer, Vec3};
    /// # fn main() -> Result<(), raytrail::Error> {
    /// // Two parallel triangles, at z = 0 and z = -1.
    /// let vertices = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0], [1.0, 0.0, -1.0], [0.0, 1.0, -1.0]];
    /// let tracer = Tracer::new(&vertices, &[[0, 1, 2], [3, 4, 5]])?;
    /// let ray = Ray::new(Vec3::new(0.25, 0.25, 1.0), -Vec3::Z, 0.0, f32::INFINITY);
    /// let lists = tracer.intersect_all(&[ray], &AllHitsOptions::default())?;
    /// let hits: Vec<(u32, f32)> = lists.ray(0).unwrap().iter().map(|h| (h.prim, h.t)).collect();
    /// assert_eq!(hits, [(0, 1.0), (1, 2.0)]);
    /// # Ok(())
    /// # }
    /// ```
    ///
    /// The lists come from the scene's wide tree: [`Error::NotPrepared`](raytrail_core::Error::NotPrepared)
    /// for a tracer built for a BVH2, kd or stream method alone ([`TracerBuilder::method`]).
    pub fn intersect_all(&self, rays: &[Ray], options: &AllHitsOptions) -> Result<AllHits, Error> {
        if self.reject_untraceable {
            if let Some(first) = rays.iter().position(|r| !r.is_traceable()) {
                let count = raytrail_core::trace::count_untraceable(&rays[first..]);
                return Err(Error::UntraceableRays { count, first });
            }
        }
        Ok(self.backend.all_hits(&self.scene, rays, options)?)
    }

    /// The point of the mesh nearest to each of `points` within distance `radius` (inclusive;
    /// `f32::INFINITY` for the whole mesh): its triangle, barycentric weights, position and
    /// distance, or `None` where no triangle comes that close (and for a point that is not
    /// finite). Ties go to the lower primitive id. [`Error::InvalidRadius`] for a NaN or negative
    /// radius; the tree is the one [`Tracer::intersect_all`] walks.
    ///
    /// ```
    /// use raytrail::Tracer;
    /// # fn main() -> Result<(), raytrail::Error> {
    /// let tracer = Tracer::new(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], &[[0, 1, 2]])?;
    /// let near = tracer.nearest_points(&[[0.25, 0.25, 2.0], [5.0, 0.0, 0.0]], 3.0)?;
    /// assert_eq!(near[0].map(|n| (n.prim, n.point, n.distance)), Some((0, [0.25, 0.25, 0.0], 2.0)));
    /// assert_eq!(near[1], None, "4 from the triangle, beyond the radius");
    /// # Ok(())
    /// # }
    /// ```
    pub fn nearest_points(&self, points: &[[f32; 3]], radius: f32) -> Result<Vec<Option<NearestPoint>>, Error> {
        if radius.is_nan() || radius < 0.0 {
            return Err(Error::InvalidRadius(radius));
        }
        Ok(self.backend.nearest_points(&self.scene, points, radius)?)
    }

    /// Moves the scene's triangles to new vertex positions (the same triangles by index, as an
    /// animation frame or a simulation step gives them): the tree is refitted in linear time
    /// rather than built again ([`PreparedScene::refit`]). Hits afterwards are bit for bit those
    /// of a tracer built from the new vertices; tracing slows as the triangles move far from where
    /// the tree was built, and a new tracer is then the faster choice. An error (another triangle
    /// count, an index out of range, a vertex that is not finite) leaves the tracer as it was.
    ///
    /// ```
    /// use raytrail::{Ray, Tracer, Vec3};
    /// # fn main() -> Result<(), raytrail::Error> {
    /// let triangle = [[0, 1, 2]];
    /// let mut tracer = Tracer::new(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], &triangle)?;
    /// // The triangle moves up by 0.5: the ray from z = 1 now meets it at t = 0.5.
    /// tracer.refit(&[[0.0, 0.0, 0.5], [1.0, 0.0, 0.5], [0.0, 1.0, 0.5]], &triangle)?;
    /// let hit = tracer.intersect_one(&Ray::new(Vec3::new(0.25, 0.25, 1.0), -Vec3::Z, 0.0, f32::INFINITY))?;
    /// assert_eq!(hit.map(|h| h.t), Some(0.5));
    /// # Ok(())
    /// # }
    /// ```
    pub fn refit(&mut self, vertices: &[[f32; 3]], triangles: &[[u32; 3]]) -> Result<(), Error> {
        self.refit_scene(&Scene::from_indexed(vertices, triangles)?)
    }

    /// [`Tracer::refit`] to a loaded mesh's vertices.
    pub fn refit_mesh(&mut self, mesh: &Mesh) -> Result<(), Error> {
        self.refit_scene(&mesh.to_scene()?)
    }

    /// [`Tracer::refit`] to a scene of the same number of triangles.
    pub fn refit_scene(&mut self, scene: &Scene) -> Result<(), Error> {
        // A prepared scene the caller still holds ([`Tracer::prepared`]) is copied, not changed.
        self.backend.refit(Arc::make_mut(&mut self.scene.0), scene)?;
        // The choices were made on the old tree.
        self.plans.get_mut().unwrap_or_else(PoisonError::into_inner).clear();
        Ok(())
    }

    /// The method this tracer would trace `rays` with for `query`: the one it was built for, or
    /// for a batch of at least [`AUTO_MIN_RAYS`] rays, the walk for sorted rays where it sorts the
    /// batch ([`crate::analysis::order::sorted_walk`]: large, in no useful order, slow per ray)
    /// and otherwise the fastest of [`AUTO_WALKS`] on a sample. The choice for a kind of batch
    /// (query, size to a power of two, order) is kept and serves the next
    /// [`REUSES`](crate::analysis::plans::REUSES) calls of that kind before it is made again.
    pub fn method_for(&self, rays: &[Ray], query: Query) -> Result<Method, Error> {
        Ok(self.plan_for(rays, query)?.0)
    }

    /// [`Tracer::method_for`] with the order the batch is traced in: sorted where `auto` sorts it.
    fn plan_for(&self, rays: &[Ray], query: Query) -> Result<(Method, TraceOrder), Error> {
        Ok(match self.method {
            Some(m) => (m, TraceOrder::AsGiven),
            None if rays.len() >= AUTO_MIN_RAYS => {
                let kind = BatchKind::of(rays, query);
                let kept = self.plans.lock().unwrap_or_else(PoisonError::into_inner).reuse(kind);
                if let Some(plan) = kept {
                    return Ok(plan);
                }
                // Chosen without the lock held: another thread's call of another kind need not wait.
                let plan = match crate::analysis::order::sorted_walk(&self.backend, &self.scene, rays, query)?.0 {
                    Some(m) => (m, TraceOrder::Sorted),
                    None => (
                        choose_among(&AUTO_WALKS, &self.backend, &self.scene, rays, query)?.method,
                        TraceOrder::AsGiven,
                    ),
                };
                self.plans.lock().unwrap_or_else(PoisonError::into_inner).keep(kind, plan);
                plan
            }
            None => (AUTO_WALKS[0], TraceOrder::AsGiven),
        })
    }

    fn trace(&self, rays: &[Ray], query: Query, hits: &mut [Hit]) -> Result<Report, Error> {
        raytrail_core::trace::check_buffers(rays, hits)?;
        if self.reject_untraceable {
            if let Some(first) = rays.iter().position(|r| !r.is_traceable()) {
                let count = raytrail_core::trace::count_untraceable(&rays[first..]);
                return Err(Error::UntraceableRays { count, first });
            }
        }
        // `auto` also picks the order: a large, slow batch in no useful order is sorted first.
        let (method, order) = self.plan_for(rays, query)?;
        Ok(self.backend.trace(&self.scene, rays, &TraceOptions::new(method).query(query).order(order), hits)?)
    }
}

/// A single ray's answer: `None` for a miss, an error for a refused ray.
fn one(hit: Hit) -> Result<Option<Hit>, Error> {
    if hit.is_refused() {
        Err(Error::RefusedRay)
    } else {
        Ok(hit.is_hit().then_some(hit))
    }
}
