//! `raytrail._raytrail`: the native half of the `raytrail` Python package.
//!
//! A [`Scene`] wraps one [`raytrail::Tracer`] (the default, `auto`) plus one more per method a
//! caller names, built on first use. Arrays come in through NumPy: every input is checked here
//! and a bad one is a Python exception naming the argument (`TypeError` for a wrong dtype,
//! `ValueError` for a wrong shape or value); nothing a caller passes can panic. The GIL is
//! released while rays are packed, traced and unpacked.

use numpy::ndarray::{ArrayView1, ArrayView2, Axis, Ix1, Ix2};
use numpy::npyffi;
use numpy::{
    dtype, IntoPyArray, PyArray1, PyArray2, PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn,
    PyUntypedArray, PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyFileNotFoundError, PyOSError, PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyTuple;
use raytrail::{AllHits, AllHitsOptions, Hit, Method, Ray, Tracer};
use std::cell::Cell;
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

mod instances;

/// Rays this process has packed into a buffer of its own (every call but the no-copy one):
/// `_raytrail._packed_rays()`, for the test that the (N, 8) float32 C-contiguous path copies
/// nothing.
static RAYS_PACKED: AtomicU64 = AtomicU64::new(0);

/// `prim` of a ray the tracer refused to answer: its origin lies more than about 4e9 (2^32) times
/// the scene's size away, where no method answers exactly (its `t` is NaN). A miss is `-1`.
const REFUSED: i64 = -2;

/// A raytrail error as the Python exception that fits it: a missing file is
/// `FileNotFoundError`, another I/O failure `OSError`, a thread pool that cannot start
/// `RuntimeError`, everything else (an empty mesh, a bad index, a NaN coordinate, a malformed
/// file) `ValueError`.
fn py_err(e: raytrail::Error) -> PyErr {
    let msg = e.to_string();
    // The I/O cause, if any, sits somewhere down the chain (raytrail::Error -> MeshError -> io).
    let mut io = None;
    let mut cause = std::error::Error::source(&e);
    while let Some(c) = cause {
        if let Some(i) = c.downcast_ref::<std::io::Error>() {
            io = Some(i);
            break;
        }
        cause = c.source();
    }
    match (&e, io) {
        (_, Some(io)) if io.kind() == std::io::ErrorKind::NotFound => PyFileNotFoundError::new_err(msg),
        (_, Some(_)) => PyOSError::new_err(msg),
        (raytrail::Error::ThreadPool(_), _) => PyRuntimeError::new_err(msg),
        _ => PyValueError::new_err(msg),
    }
}

fn value_error(msg: String) -> PyErr {
    PyValueError::new_err(msg)
}

/// The names of every method the tracer knows, in `Method::ALL`'s order (without `"auto"`).
fn method_names() -> Vec<&'static str> {
    Method::ALL.iter().map(|m| m.name()).collect()
}

/// The error of an `occluded` call with `refused` rays too far from the scene to answer as a
/// bool (`intersect` marks them instead).
fn refused_error(refused: usize) -> PyErr {
    value_error(format!(
        "rays: {refused} ray(s) start over about 4e9 times the scene's size away, where no method answers \
         exactly; intersect() marks them with prim = raytrail.REFUSED"
    ))
}

/// `obj` as a NumPy array: an array as it is, anything else through `numpy.asarray` (lists,
/// tuples, objects with `__array__`). What NumPy cannot read as an array is a `TypeError`.
fn as_array<'py>(obj: &Bound<'py, PyAny>, name: &str) -> PyResult<Bound<'py, PyUntypedArray>> {
    if let Ok(a) = obj.cast::<PyUntypedArray>() {
        return Ok(a.clone());
    }
    let py = obj.py();
    let asarray = numpy_attr(py, "asarray")?;
    let a =
        asarray.call1((obj,)).map_err(|e| PyTypeError::new_err(format!("{name}: cannot be read as an array ({e})")))?;
    a.cast_into::<PyUntypedArray>().map_err(|_| PyTypeError::new_err(format!("{name}: cannot be read as an array")))
}

fn numpy_attr<'py>(py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
    static NUMPY: PyOnceLock<Py<PyModule>> = PyOnceLock::new();
    NUMPY.get_or_try_init(py, || py.import("numpy").map(Bound::unbind))?.bind(py).getattr(name)
}

/// A real-valued array read as `f32` or `f64` without a copy where its dtype is one of those
/// (in native byte order); other real dtypes (integers, `float16`, `longdouble`, swapped byte
/// order) are converted to `float64` once.
enum Reals<'py> {
    F32(PyReadonlyArrayDyn<'py, f32>),
    F64(PyReadonlyArrayDyn<'py, f64>),
}

impl<'py> Reals<'py> {
    /// Rule: floats and integers are coordinates; booleans, complex numbers, strings, objects and
    /// dates are not, and are a `TypeError` rather than a silent cast.
    fn new(obj: &Bound<'py, PyAny>, name: &str) -> PyResult<Self> {
        let py = obj.py();
        let mut a = as_array(obj, name)?;
        let dt = a.dtype();
        match dt.kind() {
            b'f' | b'i' | b'u' => {}
            _ => {
                return Err(PyTypeError::new_err(format!(
                    "{name}: expected real numbers (a float or integer dtype), got dtype {dt}"
                )))
            }
        }
        // An unaligned buffer (a view into packed bytes) cannot be read in place: copy it.
        let aligned = unsafe { (*a.as_array_ptr()).flags & npyffi::NPY_ARRAY_ALIGNED != 0 };
        if dt.is_equiv_to(&dtype::<f32>(py)) && aligned {
            return Ok(Reals::F32(borrow(&a, name)?));
        }
        if !(dt.is_equiv_to(&dtype::<f64>(py)) && aligned) {
            a = a.call_method1("astype", ("float64",))?.cast_into::<PyUntypedArray>()?;
        }
        Ok(Reals::F64(borrow(&a, name)?))
    }

    fn shape(&self) -> &[usize] {
        match self {
            Reals::F32(a) => a.shape(),
            Reals::F64(a) => a.shape(),
        }
    }

    /// The array as a view of `f32` or `f64` rows of `width` columns: `(n, width)` as it is,
    /// `(width,)` as one row. Any memory order and strides.
    fn rows(&self, width: usize, name: &str) -> PyResult<Rows<'_>> {
        let shape = self.shape();
        // (N, width) rows; (width,) is one row; an empty 1-D array (`[]`) is no rows.
        let ok = matches!(shape, [_, w] if *w == width) || matches!(shape, [w] if *w == width || *w == 0);
        if !ok {
            return Err(value_error(format!("{name}: expected shape (N, {width}), got {}", shape_str(shape))));
        }
        // A 1-D row becomes a batch of one; a 2-D array keeps its strides (C, Fortran or any).
        fn two<T>(a: numpy::ndarray::ArrayViewD<'_, T>, width: usize) -> ArrayView2<'_, T> {
            if a.ndim() == 1 && a.is_empty() {
                a.into_shape_with_order((0, width)).expect("an empty array takes any empty shape")
            } else if a.ndim() == 1 {
                a.into_dimensionality::<Ix1>().expect("checked: one dimension").insert_axis(Axis(0))
            } else {
                a.into_dimensionality::<Ix2>().expect("checked: two dimensions")
            }
        }
        Ok(match self {
            Reals::F32(a) => Rows::F32(two(a.as_array(), width)),
            Reals::F64(a) => Rows::F64(two(a.as_array(), width)),
        })
    }

    /// A one-dimensional array of `n` values.
    fn column(&self, n: usize, name: &str) -> PyResult<Column<'_>> {
        let shape = self.shape();
        if shape != [n] {
            return Err(value_error(format!(
                "{name}: expected a scalar or shape ({n},) (one value per ray), got {}",
                shape_str(shape)
            )));
        }
        Ok(match self {
            Reals::F32(a) => Column::F32(a.as_array().into_dimensionality::<Ix1>().expect("checked: one dimension")),
            Reals::F64(a) => Column::F64(a.as_array().into_dimensionality::<Ix1>().expect("checked: one dimension")),
        })
    }
}

fn borrow<'py, T: numpy::Element>(a: &Bound<'py, PyUntypedArray>, name: &str) -> PyResult<PyReadonlyArrayDyn<'py, T>> {
    a.cast::<PyArrayDyn<T>>()?.try_readonly().map_err(|e| value_error(format!("{name}: {e}")))
}

/// An integer array read as `i64` or `u64` (the signed or unsigned kind of its dtype), without a
/// copy where it already is one of those in native byte order and aligned. Rule: indices, ids
/// and masks are integers, so a float array is a `TypeError` (a silent cast would hide a swapped
/// argument), and so are booleans.
enum Ints<'py> {
    I64(PyReadonlyArrayDyn<'py, i64>),
    U64(PyReadonlyArrayDyn<'py, u64>),
}

impl<'py> Ints<'py> {
    /// `a` as integers; `what` says what its values are, for the `TypeError` of another dtype.
    fn new(a: Bound<'py, PyUntypedArray>, name: &str, what: &str) -> PyResult<Self> {
        let py = a.py();
        let dt = a.dtype();
        let aligned = unsafe { (*a.as_array_ptr()).flags & npyffi::NPY_ARRAY_ALIGNED != 0 };
        let as_kind =
            |a: Bound<'py, PyUntypedArray>, native: bool, kind: &str| -> PyResult<Bound<'py, PyUntypedArray>> {
                if native && aligned {
                    Ok(a)
                } else {
                    Ok(a.call_method1("astype", (kind,))?.cast_into::<PyUntypedArray>()?)
                }
            };
        match dt.kind() {
            // An empty list reaches here as an empty float64 array: it holds no non-integer.
            b'f' if a.len() == 0 => Ok(Ints::I64(borrow(&as_kind(a, false, "int64")?, name)?)),
            b'i' => Ok(Ints::I64(borrow(&as_kind(a, dt.is_equiv_to(&dtype::<i64>(py)), "int64")?, name)?)),
            b'u' => Ok(Ints::U64(borrow(&as_kind(a, dt.is_equiv_to(&dtype::<u64>(py)), "uint64")?, name)?)),
            _ => Err(PyTypeError::new_err(format!("{name}: expected an integer dtype ({what}), got dtype {dt}"))),
        }
    }

    fn shape(&self) -> &[usize] {
        match self {
            Ints::I64(a) => a.shape(),
            Ints::U64(a) => a.shape(),
        }
    }

    /// Every value in memory order as `u32`, or a `ValueError` naming the first out of range
    /// (`{name}[i]`, `i` its flat index; `{name}` alone for a 0-d array).
    fn to_u32(&self, name: &str, what: &str) -> PyResult<Vec<u32>> {
        let scalar = self.shape().is_empty();
        let check = |i: usize, x: i128| {
            u32::try_from(x).map_err(|_| {
                let at = if scalar { name.to_string() } else { format!("{name}[{i}]") };
                value_error(format!("{at} = {x}: out of range; {what} run from 0 to {}", u32::MAX))
            })
        };
        match self {
            Ints::I64(a) => a.as_array().iter().enumerate().map(|(i, &x)| check(i, i128::from(x))).collect(),
            Ints::U64(a) => a.as_array().iter().enumerate().map(|(i, &x)| check(i, i128::from(x))).collect(),
        }
    }
}

fn shape_str(shape: &[usize]) -> String {
    match shape {
        [n] => format!("({n},)"),
        _ => format!("({})", shape.iter().map(|s| s.to_string()).collect::<Vec<_>>().join(", ")),
    }
}

/// Rows of coordinates, `f32` or `f64`, in any memory order.
enum Rows<'a> {
    F32(ArrayView2<'a, f32>),
    F64(ArrayView2<'a, f64>),
}

impl Rows<'_> {
    fn len(&self) -> usize {
        match self {
            Rows::F32(a) => a.nrows(),
            Rows::F64(a) => a.nrows(),
        }
    }

    /// Element `(i, j)` rounded to the nearest `f32` (what the tracer computes in).
    #[inline(always)]
    fn get(&self, i: usize, j: usize) -> f32 {
        match self {
            Rows::F32(a) => a[[i, j]],
            Rows::F64(a) => a[[i, j]] as f32,
        }
    }
}

/// One value per ray, `f32` or `f64`, any stride.
enum Column<'a> {
    F32(ArrayView1<'a, f32>),
    F64(ArrayView1<'a, f64>),
}

/// `tmin` or `tmax`: one value for every ray, or one per ray.
enum Bound1<'a> {
    Scalar(f32),
    PerRay(Column<'a>),
}

impl Bound1<'_> {
    #[inline(always)]
    fn get(&self, i: usize) -> f32 {
        match self {
            Bound1::Scalar(x) => *x,
            Bound1::PerRay(Column::F32(a)) => a[i],
            Bound1::PerRay(Column::F64(a)) => a[i] as f32,
        }
    }
}

/// A scalar bound, or the array holding one bound per ray (kept for [`Bound1::PerRay`]).
enum BoundArg<'py> {
    Scalar(f32),
    Array(Reals<'py>),
}

impl<'py> BoundArg<'py> {
    fn new(obj: Option<&Bound<'py, PyAny>>, default: f32, name: &str) -> PyResult<Self> {
        let Some(obj) = obj else { return Ok(BoundArg::Scalar(default)) };
        // An array of one or more dimensions is per ray (a 0-d array is a scalar): NumPy would
        // also convert a one-element array to a float, which would hide a shape mistake.
        if let Ok(a) = obj.cast::<PyUntypedArray>() {
            if a.ndim() > 0 {
                return Ok(BoundArg::Array(Reals::new(obj, name)?));
            }
        }
        if obj.cast::<pyo3::types::PyBool>().is_ok() {
            return Err(PyTypeError::new_err(format!("{name}: expected a number or an array, got a bool")));
        }
        if let Ok(x) = obj.extract::<f64>() {
            return Ok(BoundArg::Scalar(x as f32));
        }
        // Lists and other sequences: as arrays, one value per ray.
        Ok(BoundArg::Array(Reals::new(obj, name)?))
    }

    fn view(&self, n: usize, name: &str) -> PyResult<Bound1<'_>> {
        Ok(match self {
            BoundArg::Scalar(x) => Bound1::Scalar(*x),
            BoundArg::Array(a) => Bound1::PerRay(a.column(n, name)?),
        })
    }
}

/// The rays of one call: borrowed from the caller's `(N, 8)` float32 C-contiguous array, or
/// packed here from whatever else was given (into this thread's buffer, see [`RAY_BUF`]).
enum Rays<'a> {
    Borrowed(&'a [Ray]),
    Owned(Vec<Ray>),
}

impl Rays<'_> {
    fn as_slice(&self) -> &[Ray] {
        match self {
            Rays::Borrowed(r) => r,
            Rays::Owned(r) => r,
        }
    }
}

impl Drop for Rays<'_> {
    fn drop(&mut self) {
        if let Rays::Owned(v) = self {
            keep(&RAY_BUF, std::mem::take(v));
        }
    }
}

/// Buffers kept of at most this many rays (48 MB with their hits).
const KEEP_RAYS: usize = 1 << 20;

thread_local! {
    /// Packed rays and hit slots of the last call on this thread, kept for the next one when no
    /// larger than [`KEEP_RAYS`]: a fresh buffer of a million rays is 48 MB that the kernel maps
    /// and zeroes page by page on every call, a third of a call's time on a small scene.
    static RAY_BUF: Cell<Vec<Ray>> = const { Cell::new(Vec::new()) };
    static HIT_BUF: Cell<Vec<Hit>> = const { Cell::new(Vec::new()) };
}

/// Puts a buffer back for the next call on this thread, if it is small enough to keep.
fn keep<T>(slot: &'static std::thread::LocalKey<Cell<Vec<T>>>, mut v: Vec<T>) {
    if v.capacity() <= KEEP_RAYS {
        v.clear();
        slot.set(v);
    }
}

/// What a call's arguments hold, checked, before any ray is packed.
enum RayArgs<'py> {
    /// `(N, 8)` rows: origin, tmin, direction, tmax (the command line's `.npy` ray layout).
    Packed(Reals<'py>),
    /// Origins and directions `(N, 3)`, bounds scalar or per ray.
    Split { origins: Reals<'py>, directions: Reals<'py>, tmin: BoundArg<'py>, tmax: BoundArg<'py> },
}

impl<'py> RayArgs<'py> {
    fn new(
        origins: &Bound<'py, PyAny>,
        directions: Option<&Bound<'py, PyAny>>,
        tmin: Option<&Bound<'py, PyAny>>,
        tmax: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Self> {
        match directions {
            None => {
                // Rule: a ray array carries its own bounds; a second source would be ambiguous.
                if tmin.is_some() || tmax.is_some() {
                    return Err(value_error(
                        "tmin, tmax: a ray array (N, 8) carries them in columns 3 and 7; pass them there, \
                         or pass origins and directions"
                            .into(),
                    ));
                }
                let rays = Reals::new(origins, "rays")?;
                if !matches!(rays.shape(), [_, 8] | [8]) {
                    return Err(value_error(format!(
                        "rays: without directions the first argument must be a ray array of shape (N, 8) \
                         (origin, tmin, direction, tmax), got {}",
                        shape_str(rays.shape())
                    )));
                }
                Ok(RayArgs::Packed(rays))
            }
            Some(d) => Ok(RayArgs::Split {
                origins: Reals::new(origins, "origins")?,
                directions: Reals::new(d, "directions")?,
                tmin: BoundArg::new(tmin, 0.0, "tmin")?,
                tmax: BoundArg::new(tmax, f32::INFINITY, "tmax")?,
            }),
        }
    }
}

/// Checked views of the arguments, ready to pack without the GIL.
enum RayViews<'a> {
    Packed(Rows<'a>, Option<&'a [Ray]>),
    Split { o: Rows<'a>, d: Rows<'a>, tmin: Bound1<'a>, tmax: Bound1<'a> },
}

impl<'a> RayViews<'a> {
    fn new(args: &'a RayArgs<'_>) -> PyResult<Self> {
        match args {
            RayArgs::Packed(r) => {
                // The no-copy path: float32 in native order, C-contiguous, aligned (checked by
                // Reals::new), 8 floats a row: exactly the memory of `[Ray]`.
                let borrowed = match r {
                    Reals::F32(a) if a.is_c_contiguous() => {
                        a.as_slice().ok().and_then(|s| bytemuck::try_cast_slice::<f32, Ray>(s).ok())
                    }
                    _ => None,
                };
                Ok(RayViews::Packed(r.rows(8, "rays")?, borrowed))
            }
            RayArgs::Split { origins, directions, tmin, tmax } => {
                let o = origins.rows(3, "origins")?;
                let d = directions.rows(3, "directions")?;
                if o.len() != d.len() {
                    return Err(value_error(format!(
                        "origins and directions: {} origins but {} directions; expected one of each per ray",
                        o.len(),
                        d.len()
                    )));
                }
                let n = o.len();
                Ok(RayViews::Split { tmin: tmin.view(n, "tmin")?, tmax: tmax.view(n, "tmax")?, o, d })
            }
        }
    }

    fn len(&self) -> usize {
        match self {
            RayViews::Packed(r, _) => r.len(),
            RayViews::Split { o, .. } => o.len(),
        }
    }

    /// The rays: the caller's memory where it already is `[Ray]`, else one packing pass into
    /// this thread's buffer.
    fn rays(&self) -> Rays<'a> {
        if let RayViews::Packed(_, Some(b)) = self {
            return Rays::Borrowed(b);
        }
        RAYS_PACKED.fetch_add(self.len() as u64, Ordering::Relaxed);
        let mut out = RAY_BUF.take();
        out.clear();
        out.reserve(self.len());
        match self {
            RayViews::Packed(_, Some(_)) => unreachable!("returned above"),
            RayViews::Packed(r, None) => out.extend((0..r.len()).map(|i| Ray {
                origin: [r.get(i, 0), r.get(i, 1), r.get(i, 2)],
                tmin: r.get(i, 3),
                dir: [r.get(i, 4), r.get(i, 5), r.get(i, 6)],
                tmax: r.get(i, 7),
            })),
            RayViews::Split { o, d, tmin, tmax } => match (o, d) {
                // The common inputs, C-contiguous float64 or float32 origins and directions,
                // straight from their slices: no per-element index checks, the loop vectorizes.
                (Rows::F64(a), Rows::F64(b)) if a.is_standard_layout() && b.is_standard_layout() => pack_slices(
                    a.as_slice().expect("standard layout"),
                    b.as_slice().expect("standard layout"),
                    tmin,
                    tmax,
                    &mut out,
                ),
                (Rows::F32(a), Rows::F32(b)) if a.is_standard_layout() && b.is_standard_layout() => pack_slices(
                    a.as_slice().expect("standard layout"),
                    b.as_slice().expect("standard layout"),
                    tmin,
                    tmax,
                    &mut out,
                ),
                _ => out.extend((0..o.len()).map(|i| Ray {
                    origin: [o.get(i, 0), o.get(i, 1), o.get(i, 2)],
                    tmin: tmin.get(i),
                    dir: [d.get(i, 0), d.get(i, 1), d.get(i, 2)],
                    tmax: tmax.get(i),
                })),
            },
        }
        Rays::Owned(out)
    }
}

/// A coordinate type the rays may come in, rounded to the `f32` the tracer computes in.
trait Coord: Copy {
    fn f32(self) -> f32;
}

impl Coord for f32 {
    #[inline(always)]
    fn f32(self) -> f32 {
        self
    }
}

impl Coord for f64 {
    #[inline(always)]
    fn f32(self) -> f32 {
        self as f32
    }
}

/// Rays from origins and directions held as `3n` contiguous coordinates each, onto `out`.
fn pack_slices<T: Coord>(o: &[T], d: &[T], tmin: &Bound1<'_>, tmax: &Bound1<'_>, out: &mut Vec<Ray>) {
    out.extend(o.chunks_exact(3).zip(d.chunks_exact(3)).enumerate().map(|(i, (o, d))| Ray {
        origin: [o[0].f32(), o[1].f32(), o[2].f32()],
        tmin: tmin.get(i),
        dir: [d[0].f32(), d[1].f32(), d[2].f32()],
        tmax: tmax.get(i),
    }));
}

/// A triangle mesh ready to trace: the tree is built once, here; every call traces on all
/// cores (or on the `threads` given) with the GIL released.
///
/// Scene(vertices, faces, *, threads=None)
///
/// vertices: (n, 3) array of real numbers (float32 or float64; any integer dtype), C or Fortran
///     order; converted once to float32, the precision the tracer computes in.
/// faces: (m, 3) array of any integer dtype: each row names three vertices by index; the
///     primitive id of a hit is the row's index.
/// threads: trace on a pool of this many threads of the scene's own; ``None`` shares one pool
///     of all cores among scenes.
///
/// Raises TypeError for a non-numeric dtype (or non-integer faces), ValueError for a wrong
/// shape, a NaN or infinite coordinate (or one beyond float32's range), a negative or
/// out-of-range index, or no faces at all.
///
/// A Scene pickles compactly as its vertices (float32) and faces (uint32): the tree is not
/// shipped but rebuilt on unpickling.
#[pyclass(frozen, module = "raytrail", name = "Scene")]
struct Scene {
    vertices: Vec<[f32; 3]>,
    faces: Vec<[u32; 3]>,
    threads: Option<usize>,
    /// The default tracer: the 8-wide tree, its walk chosen per batch (`method="auto"`).
    auto: Arc<Tracer>,
    /// Tracers for named methods, each prepared on first use (a tree build of its own).
    named: Mutex<Vec<(&'static str, Arc<Tracer>)>>,
}

impl Scene {
    fn build(vertices: Vec<[f32; 3]>, faces: Vec<[u32; 3]>, threads: Option<usize>, py: Python<'_>) -> PyResult<Self> {
        if faces.is_empty() {
            return Err(value_error(format!(
                "faces: the mesh is empty ({} vertices, 0 faces); a scene needs at least one triangle",
                vertices.len()
            )));
        }
        if threads == Some(0) {
            return Err(value_error("threads: must be at least 1 (or None for all cores)".into()));
        }
        let auto = py
            .detach(|| {
                let mut b = Tracer::builder();
                if let Some(n) = threads {
                    b = b.threads(n);
                }
                b.build(&vertices, &faces)
            })
            .map_err(py_err)?;
        Ok(Scene { vertices, faces, threads, auto: Arc::new(auto), named: Mutex::new(Vec::new()) })
    }

    /// The tracer for `method`: the default for `"auto"`, else the named method's (built now if
    /// this is its first call; the lock is not held while building, so a second thread asking
    /// for the same method meanwhile builds its own and the first one stored is kept).
    fn tracer(&self, method: &str, py: Python<'_>) -> PyResult<Arc<Tracer>> {
        if method == "auto" {
            return Ok(self.auto.clone());
        }
        let Some(m) = Method::from_name(method) else {
            return Err(value_error(format!(
                "method: unknown method {method:?}; expected one of auto, {}",
                method_names().join(", ")
            )));
        };
        if let Some((_, t)) = self.lock().iter().find(|(n, _)| *n == m.name()) {
            return Ok(t.clone());
        }
        let built = py
            .detach(|| {
                let mut b = Tracer::builder().method(m);
                if let Some(n) = self.threads {
                    b = b.threads(n);
                }
                b.build(&self.vertices, &self.faces)
            })
            .map_err(py_err)?;
        let mut named = self.lock();
        if let Some((_, t)) = named.iter().find(|(n, _)| *n == m.name()) {
            return Ok(t.clone());
        }
        let t = Arc::new(built);
        named.push((m.name(), t.clone()));
        Ok(t)
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Vec<(&'static str, Arc<Tracer>)>> {
        // A poisoned lock only means another thread panicked while pushing: the list is intact.
        self.named.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// The faces as `u32` triples, checked against `vertex_count`. Rule: indices are integers, so a
/// float array is a `TypeError` (a silent cast would hide a swapped argument), and a negative
/// index is an error rather than NumPy's count from the end.
fn faces_from(obj: &Bound<'_, PyAny>, vertex_count: usize) -> PyResult<Vec<[u32; 3]>> {
    let a = as_array(obj, "faces")?;
    if a.len() == 0 {
        return Err(value_error(format!(
            "faces: the mesh is empty ({vertex_count} vertices, 0 faces); a scene needs at least one triangle"
        )));
    }
    if !matches!(a.shape(), [_, 3]) {
        return Err(value_error(format!("faces: expected shape (M, 3), got {}", shape_str(a.shape()))));
    }
    // Either integer kind is read as its 64-bit form, then each index checked against the vertices.
    match Ints::new(a, "faces", "vertex indices")? {
        Ints::I64(ro) => {
            let v = ro.as_array().into_dimensionality::<Ix2>().expect("checked: two dimensions");
            face_rows(v, |idx| if idx < 0 { Err("negative vertex index") } else { Ok(idx as u64) }, vertex_count)
        }
        Ints::U64(ro) => {
            let v = ro.as_array().into_dimensionality::<Ix2>().expect("checked: two dimensions");
            face_rows(v, Ok, vertex_count)
        }
    }
}

/// The faces of an (M, 3) index array as `u32` triples: `index` turns an entry into an unsigned
/// index or says why it is none; an index must name one of the `vertex_count` vertices.
fn face_rows<T: Copy + std::fmt::Display>(
    v: ArrayView2<'_, T>,
    index: impl Fn(T) -> Result<u64, &'static str>,
    vertex_count: usize,
) -> PyResult<Vec<[u32; 3]>> {
    let bad = |i: usize, j: usize, idx: T, why: &str| value_error(format!("faces[{i}, {j}] = {idx}: {why}"));
    let past = format!("past the {vertex_count} vertices (indices run from 0 to {})", vertex_count.saturating_sub(1));
    let mut out = Vec::with_capacity(v.nrows());
    for (i, row) in v.outer_iter().enumerate() {
        let mut f = [0u32; 3];
        for (j, (&idx, slot)) in row.iter().zip(&mut f).enumerate() {
            let u = index(idx).map_err(|why| bad(i, j, idx, why))?;
            if u >= vertex_count as u64 {
                return Err(bad(i, j, idx, &past));
            }
            *slot = u as u32;
        }
        out.push(f);
    }
    Ok(out)
}

/// The vertices as `f32` triples. Rule: every coordinate must be finite in float32, the
/// precision the tree and the triangle test use; a float64 value past float32's range would
/// become infinite, so it is refused too.
fn vertices_from(obj: &Bound<'_, PyAny>) -> PyResult<Vec<[f32; 3]>> {
    let r = Reals::new(obj, "vertices")?;
    if !matches!(r.shape(), [_, 3]) {
        return Err(value_error(format!("vertices: expected shape (N, 3), got {}", shape_str(r.shape()))));
    }
    let rows = r.rows(3, "vertices")?;
    let mut out = Vec::with_capacity(rows.len());
    for i in 0..rows.len() {
        let v = [rows.get(i, 0), rows.get(i, 1), rows.get(i, 2)];
        if let Some(j) = v.iter().position(|x| !x.is_finite()) {
            let (raw, why) = match &rows {
                Rows::F64(a) if a[[i, j]].is_finite() => (a[[i, j]].to_string(), "beyond float32's range"),
                Rows::F64(a) => (a[[i, j]].to_string(), "not finite"),
                Rows::F32(a) => (a[[i, j]].to_string(), "not finite"),
            };
            return Err(value_error(format!("vertices[{i}, {j}] = {raw}: {why}")));
        }
        out.push(v);
    }
    Ok(out)
}

fn hits_type(py: Python<'_>) -> PyResult<&Bound<'_, PyAny>> {
    static HITS: PyOnceLock<Py<PyAny>> = PyOnceLock::new();
    Ok(HITS.get_or_try_init(py, || py.import("raytrail._hits")?.getattr("Hits").map(Bound::unbind))?.bind(py))
}

fn instance_hits_type(py: Python<'_>) -> PyResult<&Bound<'_, PyAny>> {
    static INSTANCE_HITS: PyOnceLock<Py<PyAny>> = PyOnceLock::new();
    Ok(INSTANCE_HITS
        .get_or_try_init(py, || py.import("raytrail._hits")?.getattr("InstanceHits").map(Bound::unbind))?
        .bind(py))
}

fn nearest_type(py: Python<'_>) -> PyResult<&Bound<'_, PyAny>> {
    static NEAREST: PyOnceLock<Py<PyAny>> = PyOnceLock::new();
    Ok(NEAREST.get_or_try_init(py, || py.import("raytrail._hits")?.getattr("Nearest").map(Bound::unbind))?.bind(py))
}

fn all_hits_type(py: Python<'_>) -> PyResult<&Bound<'_, PyAny>> {
    static ALL_HITS: PyOnceLock<Py<PyAny>> = PyOnceLock::new();
    Ok(ALL_HITS.get_or_try_init(py, || py.import("raytrail._hits")?.getattr("AllHits").map(Bound::unbind))?.bind(py))
}

/// A miss's `prim` is -1, a refused ray's [`REFUSED`], a hit's the triangle's index.
#[inline(always)]
fn prim_id(prim: u32) -> i64 {
    match prim {
        Hit::NO_PRIM => -1,
        Hit::REFUSED_PRIM => REFUSED,
        p => i64::from(p),
    }
}

#[pymethods]
impl Scene {
    #[new]
    #[pyo3(signature = (vertices, faces, *, threads=None))]
    fn new(
        py: Python<'_>,
        vertices: &Bound<'_, PyAny>,
        faces: &Bound<'_, PyAny>,
        threads: Option<usize>,
    ) -> PyResult<Self> {
        let vertices = vertices_from(vertices)?;
        let faces = faces_from(faces, vertices.len())?;
        Scene::build(vertices, faces, threads, py)
    }

    /// intersect(origins, directions=None, tmin=None, tmax=None, method="auto")
    ///
    /// The closest hit of each ray, as ``Hits(t, prim, u, v)``, four arrays of length N:
    ///
    /// - ``t`` (float32): the ray parameter of the hit, ``origin + t * direction`` (directions
    ///   need not be unit length, so ``t`` is in units of the direction's length); ``inf`` for a
    ///   miss.
    /// - ``prim`` (int64): the index of the face hit; ``-1`` for a miss (``raytrail.REFUSED``,
    ///   -2, with ``t`` NaN, for a ray whose origin lies over about 4e9 times the scene's size
    ///   away, which no method answers exactly).
    /// - ``u``, ``v`` (float32): barycentric weights of the face's second and third vertex at
    ///   the hit (the first's is ``1 - u - v``); 0 for a miss.
    ///
    /// Rays come as origins and directions, each (N, 3) (or (3,) for one ray), with ``tmin``
    /// and ``tmax`` scalars or (N,) arrays (default 0 and inf): a hit has ``tmin <= t <= tmax``.
    /// Or as one (N, 8) ray array of rows (origin, tmin, direction, tmax), the command line's
    /// layout, alone: a float32 C-contiguous one is traced in place, without a copy. Any real
    /// dtype and memory order is accepted (converted to float32 in one pass otherwise).
    ///
    /// A ray that cannot hit anything (a NaN or infinite component, a zero direction,
    /// ``tmin > tmax``) is a miss. Ties at equal ``t`` go to the lower face index.
    ///
    /// ``method``: ``"auto"`` (the default tracer, timing its walks on large batches) or any of
    /// ``raytrail.METHODS``; a named method's tree is built on its first call.
    #[pyo3(signature = (origins, directions=None, tmin=None, tmax=None, method="auto"))]
    fn intersect<'py>(
        &self,
        py: Python<'py>,
        origins: &Bound<'py, PyAny>,
        directions: Option<&Bound<'py, PyAny>>,
        tmin: Option<&Bound<'py, PyAny>>,
        tmax: Option<&Bound<'py, PyAny>>,
        method: &str,
    ) -> PyResult<Bound<'py, PyAny>> {
        let args = RayArgs::new(origins, directions, tmin, tmax)?;
        let views = RayViews::new(&args)?;
        let tracer = self.tracer(method, py)?;
        let n = views.len();
        let (t, prim, u, v) = py
            .detach(|| -> Result<_, raytrail::Error> {
                let rays = views.rays();
                let mut hits = HIT_BUF.take();
                hits.clear();
                hits.resize(n, Hit::MISS);
                if n > 0 {
                    if let Err(e) = tracer.intersect_into(rays.as_slice(), &mut hits) {
                        keep(&HIT_BUF, hits);
                        return Err(e);
                    }
                }
                let (mut t, mut prim, mut u, mut v) =
                    (Vec::with_capacity(n), Vec::with_capacity(n), Vec::with_capacity(n), Vec::with_capacity(n));
                for h in &hits {
                    t.push(h.t);
                    prim.push(prim_id(h.prim));
                    u.push(h.u);
                    v.push(h.v);
                }
                keep(&HIT_BUF, hits);
                Ok((t, prim, u, v))
            })
            .map_err(py_err)?;
        hits_type(py)?.call1((t.into_pyarray(py), prim.into_pyarray(py), u.into_pyarray(py), v.into_pyarray(py)))
    }

    /// occluded(origins, directions=None, tmin=None, tmax=None, method="auto")
    ///
    /// Whether anything blocks each ray within ``[tmin, tmax]``: a bool array of length N,
    /// True exactly where ``intersect`` finds a hit (any hit ends the search, so it is faster).
    /// Rays are given as for ``intersect``. A ray whose origin lies over about 4e9 times the
    /// scene's size away cannot be answered as a bool and raises ValueError (``intersect`` marks
    /// it instead).
    #[pyo3(signature = (origins, directions=None, tmin=None, tmax=None, method="auto"))]
    fn occluded<'py>(
        &self,
        py: Python<'py>,
        origins: &Bound<'py, PyAny>,
        directions: Option<&Bound<'py, PyAny>>,
        tmin: Option<&Bound<'py, PyAny>>,
        tmax: Option<&Bound<'py, PyAny>>,
        method: &str,
    ) -> PyResult<Bound<'py, PyArray1<bool>>> {
        let args = RayArgs::new(origins, directions, tmin, tmax)?;
        let views = RayViews::new(&args)?;
        let tracer = self.tracer(method, py)?;
        let n = views.len();
        let (out, refused) = py
            .detach(|| -> Result<_, raytrail::Error> {
                let rays = views.rays();
                let mut out = vec![false; n];
                let refused = if n > 0 { tracer.occluded_into(rays.as_slice(), &mut out)?.refused } else { 0 };
                Ok((out, refused))
            })
            .map_err(py_err)?;
        if refused > 0 {
            return Err(refused_error(refused));
        }
        Ok(out.into_pyarray(py))
    }

    /// intersect_all(origins, directions=None, tmin=None, tmax=None, *, max_hits=None, merge_equal_t=False)
    ///
    /// Every hit of each ray within ``[tmin, tmax]``, as ``AllHits(ray, t, prim, u, v,
    /// truncated)``: the hits of all rays one ray after another, each ray's in order of ``t``
    /// (ties by face index), each face at most once. ``ray`` gives the ray of each hit (as
    /// trimesh's ``index_ray``), ``truncated`` (length N) marks rays with more than ``max_hits``
    /// hits, of which the nearest are listed. A ray through an edge two faces share meets both,
    /// at one ``t``; ``merge_equal_t=True`` keeps only the lower face index of hits at one ``t``.
    /// Rays are given as for ``intersect``; the first hit of each ray is ``intersect``'s.
    #[pyo3(signature = (origins, directions=None, tmin=None, tmax=None, *, max_hits=None, merge_equal_t=false))]
    #[allow(clippy::too_many_arguments, clippy::type_complexity)]
    fn intersect_all<'py>(
        &self,
        py: Python<'py>,
        origins: &Bound<'py, PyAny>,
        directions: Option<&Bound<'py, PyAny>>,
        tmin: Option<&Bound<'py, PyAny>>,
        tmax: Option<&Bound<'py, PyAny>>,
        max_hits: Option<usize>,
        merge_equal_t: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let args = RayArgs::new(origins, directions, tmin, tmax)?;
        let views = RayViews::new(&args)?;
        let options = AllHitsOptions { max_hits: max_hits.unwrap_or(usize::MAX), merge_equal_t };
        let tracer = self.auto.clone();
        let n = views.len();
        let (ray, t, prim, u, v, truncated) = py
            .detach(|| -> Result<_, raytrail::Error> {
                let rays = views.rays();
                let lists = if n > 0 { tracer.intersect_all(rays.as_slice(), &options)? } else { AllHits::default() };
                let h = lists.hits().len();
                let (mut ray, mut t, mut prim, mut u, mut v) = (
                    Vec::with_capacity(h),
                    Vec::with_capacity(h),
                    Vec::with_capacity(h),
                    Vec::with_capacity(h),
                    Vec::with_capacity(h),
                );
                for (i, list) in lists.iter().enumerate() {
                    for hit in list {
                        ray.push(i as i64);
                        t.push(hit.t);
                        prim.push(prim_id(hit.prim));
                        u.push(hit.u);
                        v.push(hit.v);
                    }
                }
                let truncated: Vec<bool> = (0..n).map(|i| lists.is_truncated(i)).collect();
                Ok((ray, t, prim, u, v, truncated))
            })
            .map_err(py_err)?;
        all_hits_type(py)?.call1((
            ray.into_pyarray(py),
            t.into_pyarray(py),
            prim.into_pyarray(py),
            u.into_pyarray(py),
            v.into_pyarray(py),
            truncated.into_pyarray(py),
        ))
    }

    /// nearest(points, radius=inf)
    ///
    /// The point of the mesh nearest to each of N query points (an (N, 3) array of any real
    /// dtype), within distance ``radius`` (inclusive), as ``Nearest(point, distance, prim, u, v)``:
    /// ``point`` (N, 3) float32, ``distance`` float32, ``prim`` int64 (the face), ``u``, ``v``
    /// float32 (barycentric weights of the face's second and third vertex). Where no face comes
    /// within the radius, or for a point that is not finite: ``prim`` -1, ``distance`` inf,
    /// ``point`` NaN, ``u`` and ``v`` 0. Ties go to the lower face index. (trimesh's
    /// ``closest_point`` gives ``point, distance, prim`` in that order too.)
    #[pyo3(signature = (points, radius=f32::INFINITY))]
    fn nearest<'py>(&self, py: Python<'py>, points: &Bound<'py, PyAny>, radius: f32) -> PyResult<Bound<'py, PyAny>> {
        let r = Reals::new(points, "points")?;
        if !matches!(r.shape(), [_, 3]) {
            return Err(value_error(format!("points: expected shape (N, 3), got {}", shape_str(r.shape()))));
        }
        let rows = r.rows(3, "points")?;
        let pts: Vec<[f32; 3]> = (0..rows.len()).map(|i| [rows.get(i, 0), rows.get(i, 1), rows.get(i, 2)]).collect();
        if radius.is_nan() || radius < 0.0 {
            return Err(value_error(format!("radius: {radius}; must be zero or more (inf for no limit)")));
        }
        let tracer = self.auto.clone();
        let found = py.detach(|| tracer.nearest_points(&pts, radius)).map_err(py_err)?;
        let n = found.len();
        let (mut point, mut distance, mut prim, mut u, mut v) = (
            Vec::with_capacity(3 * n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        );
        for f in &found {
            match f {
                Some(f) => {
                    point.extend_from_slice(&f.point);
                    distance.push(f.distance);
                    prim.push(i64::from(f.prim));
                    u.push(f.u);
                    v.push(f.v);
                }
                None => {
                    point.extend_from_slice(&[f32::NAN; 3]);
                    distance.push(f32::INFINITY);
                    prim.push(-1);
                    u.push(0.0);
                    v.push(0.0);
                }
            }
        }
        let point = point.into_pyarray(py).reshape([n, 3])?;
        nearest_type(py)?.call1((
            point,
            distance.into_pyarray(py),
            prim.into_pyarray(py),
            u.into_pyarray(py),
            v.into_pyarray(py),
        ))
    }

    /// The vertices, (n, 3) float32 (a copy).
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f32>>> {
        let flat: &[f32] = bytemuck::cast_slice(&self.vertices);
        flat.to_vec().into_pyarray(py).reshape([self.vertices.len(), 3])
    }

    /// The faces, (m, 3) int64 (a copy); a hit's ``prim`` indexes its rows.
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let flat: Vec<i64> = self.faces.iter().flatten().map(|&i| i64::from(i)).collect();
        flat.into_pyarray(py).reshape([self.faces.len(), 3])
    }

    /// The threads of the scene's own pool, or None (the shared pool of all cores).
    #[getter]
    fn threads(&self) -> Option<usize> {
        self.threads
    }

    fn __len__(&self) -> usize {
        self.faces.len()
    }

    fn __repr__(&self) -> String {
        let threads = self.threads.map(|n| format!(", threads={n}")).unwrap_or_default();
        format!("raytrail.Scene({} vertices, {} faces{threads})", self.vertices.len(), self.faces.len())
    }

    /// Pickles as (vertices float32, faces uint32, threads): 12 bytes a vertex and 12 a face.
    /// The tree is rebuilt on unpickling rather than shipped (see the package README for the
    /// measured trade).
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let rebuild = py.import("raytrail._pickle")?.getattr("scene_from_state")?;
        let flat: &[f32] = bytemuck::cast_slice(&self.vertices);
        let vertices = flat.to_vec().into_pyarray(py).reshape([self.vertices.len(), 3])?;
        let flat: &[u32] = bytemuck::cast_slice(&self.faces);
        let faces = flat.to_vec().into_pyarray(py).reshape([self.faces.len(), 3])?;
        let state = (vertices, faces, self.threads).into_pyobject(py)?;
        PyTuple::new(py, [rebuild, state.into_any()])
    }
}

/// load(path, *, threads=None)
///
/// A Scene from a mesh file: OBJ, PLY, OFF, STL, glTF (.gltf, .glb), any of them gzipped;
/// polygons are split into triangles, other elements skipped. Raises FileNotFoundError for a
/// missing file, OSError for one that cannot be read, ValueError for a malformed one (the
/// message names the file and the line or byte).
#[pyfunction]
#[pyo3(signature = (path, *, threads=None))]
fn load(py: Python<'_>, path: PathBuf, threads: Option<usize>) -> PyResult<Scene> {
    let mesh = py.detach(|| raytrail::load(&path)).map_err(py_err)?;
    let vertices = mesh.positions.iter().map(|p| p.to_array()).collect();
    Scene::build(vertices, mesh.triangles, threads, py)
}

/// Rays packed into a buffer of the module's own so far (a test hook: the no-copy path adds 0).
#[pyfunction]
fn _packed_rays() -> u64 {
    RAYS_PACKED.load(Ordering::Relaxed)
}

/// The native half of the ``raytrail`` package; import ``raytrail`` instead.
/// The conformance crate's exact judgement of answers `prim` (int64, -1 a miss) at `t` for the
/// float32 rays `rays` (N, 8) in `scene`: per ray "exact", "near" or "disagree: why" (see
/// `raytrail_conformance::exact::verdict`). A NaN `t` stands for the ray's `t` at the plane of
/// face `prim` (for a tracer that reports only the face). A test hook (feature `exact-reference`): it lets the
/// tests judge any tracer's answers, embreex's included, by the reference the suite uses.
#[cfg(feature = "exact-reference")]
#[pyfunction]
fn _exact_judge(
    scene: &Scene,
    rays: numpy::PyReadonlyArray2<'_, f32>,
    prim: numpy::PyReadonlyArray1<'_, i64>,
    t: numpy::PyReadonlyArray1<'_, f32>,
) -> PyResult<Vec<String>> {
    use raytrail_conformance::exact::verdict::plane_t;
    use raytrail_conformance::exact::{judge, ExactScene, Judgement, Tolerance};
    let (rays, prim, t) = (rays.as_array(), prim.as_array(), t.as_array());
    if rays.ncols() != 8 || prim.len() != rays.nrows() || t.len() != rays.nrows() {
        return Err(value_error("_exact_judge: rays (N, 8), prim (N,) and t (N,) expected".into()));
    }
    let triangles: Vec<raytrail::core::geometry::Triangle> = scene
        .faces
        .iter()
        .map(|f| {
            let v = f.map(|i| raytrail::Vec3::from_array(scene.vertices[i as usize]));
            raytrail::core::geometry::Triangle::new(v[0], v[1], v[2])
        })
        .collect();
    let bounds = triangles.iter().fold(raytrail::core::Aabb::EMPTY, |b, t| b.union(t.bounds()));
    let tol = Tolerance::for_scene(bounds.max_abs());
    let exact = ExactScene::new(triangles);
    Ok((0..rays.nrows())
        .map(|i| {
            let r = rays.row(i);
            let ray = Ray { origin: [r[0], r[1], r[2]], tmin: r[3], dir: [r[4], r[5], r[6]], tmax: r[7] };
            let hit = match prim[i] {
                p if p >= 0 && (p as usize) < scene.faces.len() => {
                    let t = if t[i].is_nan() { plane_t(&ray, &exact.triangles()[p as usize]) as f32 } else { t[i] };
                    Hit { t, prim: p as u32, u: 0.0, v: 0.0 }
                }
                p if p >= 0 => Hit { t: t[i], prim: p as u32, u: 0.0, v: 0.0 },
                _ => Hit::MISS,
            };
            match judge(&ray, exact.triangles(), &exact.closest_hit(&ray), &hit, tol, false) {
                Judgement::Exact => "exact".to_string(),
                Judgement::Near => "near".to_string(),
                Judgement::Refused => "refused".to_string(),
                Judgement::Disagree(why) => format!("disagree: {why}"),
            }
        })
        .collect())
}

#[pymodule]
fn _raytrail(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add_class::<Scene>()?;
    m.add_class::<instances::InstancedScene>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(_packed_rays, m)?)?;
    #[cfg(feature = "exact-reference")]
    m.add_function(wrap_pyfunction!(_exact_judge, m)?)?;
    let names: Vec<&str> = std::iter::once("auto").chain(method_names()).collect();
    m.add("METHODS", PyTuple::new(py, names)?)?;
    m.add("REFUSED", REFUSED)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
