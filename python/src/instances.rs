//! `raytrail.InstancedScene`: meshes placed many times by affine maps, each placement with an id
//! and a 32-bit mask, over [`raytrail::InstancedTracer`] (each mesh's tree built once).
//!
//! The placements come as NumPy arrays, one row per instance (as Open3D and Embree take them):
//! the mesh of each, its transform ((K, 3, 4) rows `[A | b]`, or (K, 4, 4) homogeneous with the
//! last row `0 0 0 1`), optional ids and masks. Every array is checked here, and a bad one is a
//! Python exception naming the argument and the instance.

use super::{
    as_array, instance_hits_type, prim_id, py_err, refused_error, shape_str, value_error, Ints, RayArgs, RayViews,
    Reals, Scene,
};
use numpy::{IntoPyArray, PyArray1, PyArrayMethods};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyList, PyTuple};
use raytrail::core::scene::Scene as Mesh;
use raytrail::{Instance, InstanceHit, InstancedTracer, Method, Tracer, Transform};

/// InstancedScene(meshes, mesh, transforms, *, ids=None, masks=None, threads=None, method="bvh8-sah")
///
/// Meshes placed many times: instance ``k`` is ``meshes[mesh[k]]`` moved by ``transforms[k]``
/// (from the mesh's frame to the world). Each mesh's tree is built once however often it is
/// placed, and a tree over the placements' boxes picks the instances a ray enters.
///
/// - ``meshes``: a sequence of :class:`Scene`.
/// - ``mesh``: (K,) integers, each an index into ``meshes``.
/// - ``transforms``: (K, 3, 4) rows ``[A | b]`` (``p -> A p + b``), or (K, 4, 4) homogeneous
///   matrices whose last row is ``0 0 0 1``; any real dtype. ``A`` must be invertible.
/// - ``ids``: (K,) integers in 0..2**32-1 that hits report (default ``arange(K)``).
/// - ``masks``: (K,) integers in 0..2**32-1 (default every bit): a ray with mask ``m`` is tested
///   against instance ``k`` only where ``m & masks[k] != 0``.
/// - ``threads``: as for :class:`Scene`. ``method``: any of ``raytrail.METHODS`` but
///   ``"auto"``, the walk each mesh is traced with.
///
/// Hits agree with the same triangles flattened into one mesh to within the conformance suite's
/// edge tolerance, not bit for bit (the rays are mapped into each mesh's frame).
///
/// Raises TypeError for a wrong dtype (a non-integer ``mesh``, ``ids`` or ``masks``, a
/// ``meshes`` entry that is not a Scene), ValueError for a wrong shape, an index out of range,
/// a transform that is not finite or not invertible, or no instances.
#[pyclass(frozen, module = "raytrail", name = "InstancedScene")]
pub(crate) struct InstancedScene {
    meshes: Vec<Py<Scene>>,
    placements: Vec<Instance>,
    threads: Option<usize>,
    method: Method,
    tracer: InstancedTracer,
}

/// The transforms as rows `[A | b]`, from a (K, 3, 4) or (K, 4, 4) array.
fn transforms_from(obj: &Bound<'_, PyAny>, count: usize) -> PyResult<Vec<Transform>> {
    let a = Reals::new(obj, "transforms")?;
    let shape = a.shape().to_vec();
    let rows = match shape.as_slice() {
        [k, 3 | 4, 4] if *k == count => shape[1],
        [k, 3 | 4, 4] => {
            return Err(value_error(format!(
                "transforms: {k} transforms for {count} instances (mesh has {count} entries); expected one each"
            )))
        }
        _ => {
            return Err(value_error(format!(
                "transforms: expected shape (K, 3, 4) or (K, 4, 4), got {}",
                shape_str(&shape)
            )))
        }
    };
    drop(a);
    // As (K * rows, 4): each transform's rows one after another.
    let flat = as_array(obj, "transforms")?.call_method1("reshape", ((count * rows, 4),))?;
    let flat = Reals::new(&flat, "transforms")?;
    let view = flat.rows(4, "transforms")?;
    (0..count)
        .map(|k| {
            let row = |i: usize| -> [f32; 4] { core::array::from_fn(|j| view.get(k * rows + i, j)) };
            if rows == 4 && row(3) != [0.0, 0.0, 0.0, 1.0] {
                let r = row(3);
                return Err(value_error(format!(
                    "transforms[{k}]: the last row of a 4x4 transform must be 0 0 0 1 (an affine map), got \
                     {} {} {} {}",
                    r[0], r[1], r[2], r[3]
                )));
            }
            Ok(Transform::from_rows([row(0), row(1), row(2)]))
        })
        .collect()
}

/// One `u32` per instance from an optional (K,) integer array, or `default(k)` for each.
fn per_instance(
    obj: Option<&Bound<'_, PyAny>>,
    count: usize,
    name: &str,
    what: &str,
    default: impl Fn(usize) -> u32,
) -> PyResult<Vec<u32>> {
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok((0..count).map(default).collect());
    };
    let ints = Ints::new(as_array(obj, name)?, name, what)?;
    if ints.shape() != [count] {
        return Err(value_error(format!(
            "{name}: expected shape ({count},), one per instance, got {}",
            shape_str(ints.shape())
        )));
    }
    ints.to_u32(name, what)
}

/// The rays' masks: none, one for every ray (a scalar), or (N,) integers.
fn ray_masks(obj: Option<&Bound<'_, PyAny>>, n: usize) -> PyResult<Option<Vec<u32>>> {
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok(None);
    };
    let ints = Ints::new(as_array(obj, "masks")?, "masks", "32-bit masks")?;
    let masks = ints.to_u32("masks", "masks")?;
    match ints.shape() {
        [] => Ok(Some(vec![masks[0]; n])),
        [m] if *m == n => Ok(Some(masks)),
        s => Err(value_error(format!("masks: expected a scalar or shape ({n},), one per ray, got {}", shape_str(s)))),
    }
}

impl InstancedScene {
    /// Closest hits of the rays, with their masks where given.
    fn closest(&self, py: Python<'_>, views: &RayViews<'_>, masks: Option<&[u32]>) -> PyResult<Vec<InstanceHit>> {
        let n = views.len();
        py.detach(|| -> Result<_, raytrail::Error> {
            let rays = views.rays();
            let mut hits = vec![InstanceHit::MISS; n];
            if n > 0 {
                self.tracer.intersect_into(rays.as_slice(), masks, &mut hits)?;
            }
            Ok(hits)
        })
        .map_err(py_err)
    }

    /// Whether each ray is blocked, and how many were refused.
    fn blocked(&self, py: Python<'_>, views: &RayViews<'_>, masks: Option<&[u32]>) -> PyResult<(Vec<bool>, usize)> {
        let n = views.len();
        py.detach(|| -> Result<_, raytrail::Error> {
            let rays = views.rays();
            let mut blocked = vec![false; n];
            let refused =
                if n > 0 { self.tracer.occluded_into(rays.as_slice(), masks, &mut blocked)?.report.refused } else { 0 };
            Ok((blocked, refused))
        })
        .map_err(py_err)
    }
}

#[pymethods]
impl InstancedScene {
    #[new]
    #[pyo3(signature = (meshes, mesh, transforms, *, ids=None, masks=None, threads=None, method="bvh8-sah"))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        meshes: &Bound<'_, PyAny>,
        mesh: &Bound<'_, PyAny>,
        transforms: &Bound<'_, PyAny>,
        ids: Option<&Bound<'_, PyAny>>,
        masks: Option<&Bound<'_, PyAny>>,
        threads: Option<usize>,
        method: &str,
    ) -> PyResult<Self> {
        let meshes: Vec<Py<Scene>> = meshes
            .try_iter()
            .map_err(|_| PyTypeError::new_err("meshes: expected a sequence of raytrail.Scene"))?
            .enumerate()
            .map(|(i, m)| {
                m?.cast_into::<Scene>()
                    .map(Bound::unbind)
                    .map_err(|e| PyTypeError::new_err(format!("meshes[{i}]: expected a raytrail.Scene, got {}", e)))
            })
            .collect::<PyResult<_>>()?;
        if meshes.is_empty() {
            return Err(value_error("meshes: empty; an instanced scene needs at least one mesh".into()));
        }
        let which = Ints::new(as_array(mesh, "mesh")?, "mesh", "indices into meshes")?;
        let [count] = *which.shape() else {
            return Err(value_error(format!(
                "mesh: expected shape (K,), one mesh index per instance, got {}",
                shape_str(which.shape())
            )));
        };
        if count == 0 {
            return Err(value_error("mesh: no instances; an instanced scene needs at least one".into()));
        }
        let which = which.to_u32("mesh", "indices into meshes")?;
        if let Some(k) = which.iter().position(|&m| m as usize >= meshes.len()) {
            return Err(value_error(format!("mesh[{k}] = {}: out of range for {} mesh(es)", which[k], meshes.len())));
        }
        let transforms = transforms_from(transforms, count)?;
        let ids = per_instance(ids, count, "ids", "instance ids", |k| k as u32)?;
        let instance_masks = per_instance(masks, count, "masks", "32-bit masks", |_| u32::MAX)?;
        if threads == Some(0) {
            return Err(value_error("threads: must be at least 1 (or None for all cores)".into()));
        }
        let method = match Method::from_name(method) {
            Some(m) => m,
            None => {
                return Err(value_error(format!(
                    "method: unknown method {method:?}; expected one of {}",
                    super::method_names().join(", ")
                )))
            }
        };
        let placements: Vec<Instance> = (0..count)
            .map(|k| Instance::new(which[k], transforms[k]).with_id(ids[k]).with_mask(instance_masks[k]))
            .collect();
        let core_meshes = meshes
            .iter()
            .map(|m| {
                let m = m.get();
                Mesh::from_indexed(&m.vertices, &m.faces).map_err(|e| py_err(e.into()))
            })
            .collect::<PyResult<Vec<_>>>()?;
        let tracer = py
            .detach(|| {
                let mut b = Tracer::builder().method(method);
                if let Some(n) = threads {
                    b = b.threads(n);
                }
                b.build_instanced(&core_meshes, &placements)
            })
            .map_err(py_err)?;
        Ok(InstancedScene { meshes, placements, threads, method, tracer })
    }

    /// intersect(origins, directions=None, tmin=None, tmax=None, *, masks=None)
    ///
    /// The closest hit of each ray, as ``InstanceHits(t, prim, u, v, instance)``: ``t``, ``u``,
    /// ``v`` as in :meth:`Scene.intersect`; ``prim`` the face within the instance's mesh (-1 for
    /// a miss, ``raytrail.REFUSED`` for a ray too far away to answer); ``instance`` (int64) the
    /// id of the instance hit, -1 for a miss or a refusal. Rays are given as for
    /// :meth:`Scene.intersect`; ``masks``, a scalar or (N,) integers, leaves out of each ray the
    /// instances whose mask shares no bit with it (default: every instance).
    #[pyo3(signature = (origins, directions=None, tmin=None, tmax=None, *, masks=None))]
    fn intersect<'py>(
        &self,
        py: Python<'py>,
        origins: &Bound<'py, PyAny>,
        directions: Option<&Bound<'py, PyAny>>,
        tmin: Option<&Bound<'py, PyAny>>,
        tmax: Option<&Bound<'py, PyAny>>,
        masks: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let args = RayArgs::new(origins, directions, tmin, tmax)?;
        let views = RayViews::new(&args)?;
        let masks = ray_masks(masks, views.len())?;
        let hits = self.closest(py, &views, masks.as_deref())?;
        let t: Vec<f32> = hits.iter().map(|h| h.t).collect();
        let prim: Vec<i64> = hits.iter().map(|h| prim_id(h.prim)).collect();
        let u: Vec<f32> = hits.iter().map(|h| h.u).collect();
        let v: Vec<f32> = hits.iter().map(|h| h.v).collect();
        let instance: Vec<i64> = hits
            .iter()
            .map(|h| if h.instance == InstanceHit::NO_INSTANCE { -1 } else { i64::from(h.instance) })
            .collect();
        instance_hits_type(py)?.call1((
            t.into_pyarray(py),
            prim.into_pyarray(py),
            u.into_pyarray(py),
            v.into_pyarray(py),
            instance.into_pyarray(py),
        ))
    }

    /// occluded(origins, directions=None, tmin=None, tmax=None, *, masks=None)
    ///
    /// Whether anything blocks each ray within ``[tmin, tmax]`` (among the instances its mask
    /// admits): a bool array of length N, True exactly where ``intersect`` finds a hit. A ray
    /// too far from the scene to answer raises ValueError, as for :meth:`Scene.occluded`.
    #[pyo3(signature = (origins, directions=None, tmin=None, tmax=None, *, masks=None))]
    fn occluded<'py>(
        &self,
        py: Python<'py>,
        origins: &Bound<'py, PyAny>,
        directions: Option<&Bound<'py, PyAny>>,
        tmin: Option<&Bound<'py, PyAny>>,
        tmax: Option<&Bound<'py, PyAny>>,
        masks: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray1<bool>>> {
        let args = RayArgs::new(origins, directions, tmin, tmax)?;
        let views = RayViews::new(&args)?;
        let masks = ray_masks(masks, views.len())?;
        let (blocked, refused) = self.blocked(py, &views, masks.as_deref())?;
        if refused > 0 {
            return Err(refused_error(refused));
        }
        Ok(blocked.into_pyarray(py))
    }

    /// The meshes, as given.
    #[getter]
    fn meshes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        PyList::new(py, self.meshes.iter().map(|m| m.clone_ref(py)))
    }

    /// The mesh index of each instance, (K,) int64 (a copy).
    #[getter]
    fn mesh<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        self.placements.iter().map(|p| i64::from(p.mesh)).collect::<Vec<_>>().into_pyarray(py)
    }

    /// The transforms, (K, 3, 4) float32 rows ``[A | b]`` (a copy).
    #[getter]
    fn transforms<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let flat: Vec<f32> = self.placements.iter().flat_map(|p| p.transform.rows.into_iter().flatten()).collect();
        Ok(flat.into_pyarray(py).reshape([self.placements.len(), 3, 4])?.into_any())
    }

    /// The instance ids, (K,) int64 (a copy).
    #[getter]
    fn ids<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        self.placements.iter().map(|p| i64::from(p.id)).collect::<Vec<_>>().into_pyarray(py)
    }

    /// The instance masks, (K,) uint32 (a copy).
    #[getter]
    fn masks<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u32>> {
        self.placements.iter().map(|p| p.mask).collect::<Vec<_>>().into_pyarray(py)
    }

    /// The threads of the scene's own pool, or None (the shared pool of all cores).
    #[getter]
    fn threads(&self) -> Option<usize> {
        self.threads
    }

    /// The method each mesh is traced with.
    #[getter]
    fn method(&self) -> &'static str {
        self.method.name()
    }

    /// The number of instances.
    fn __len__(&self) -> usize {
        self.placements.len()
    }

    fn __repr__(&self) -> String {
        let threads = self.threads.map(|n| format!(", threads={n}")).unwrap_or_default();
        format!(
            "raytrail.InstancedScene({} mesh(es), {} instances, method={:?}{threads})",
            self.meshes.len(),
            self.placements.len(),
            self.method.name()
        )
    }

    /// Pickles as its meshes (each as a Scene pickles) and the placement arrays; the trees are
    /// rebuilt on unpickling.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let rebuild = py.import("raytrail._pickle")?.getattr("instanced_from_state")?;
        let masks = self.masks(py);
        let state = (
            self.meshes(py)?,
            self.mesh(py),
            self.transforms(py)?,
            self.ids(py),
            masks,
            self.threads,
            self.method.name(),
        )
            .into_pyobject(py)?;
        PyTuple::new(py, [rebuild, state.into_any()])
    }
}
