//! The exact reference: each ray's true closest hit, decided without floating-point doubt.
//!
//! Every `f32` is a dyadic rational, so a ray and a triangle given in `f32` can be intersected
//! exactly in integers ([`dyadic`], [`triangle`]). The reference is a brute force over all
//! triangles ([`closest`]), accelerated only by an `f64` filter with a proven error bound
//! ([`filter`]) that decides a triangle only where its bound is conclusive and hands every other
//! one to the exact test. It shares no code with the traversals, so it cannot share their bugs.
//!
//! What "the answer" is, precisely ([`closest::ExactAnswer`]):
//! - A ray hits a triangle when the exact point `o + t d` lies in the closed triangle (edges and
//!   vertices included) at a `t` in `[tmin, tmax]` (inclusive), and the ray is not parallel to
//!   the triangle's plane (a ray in the plane is no hit): the watertight test's convention, exact.
//! - The closest `t` is exact (a rational). Every triangle hit at exactly that `t` is a winner: a
//!   ray through a shared edge or vertex has several. The project's tie rule (equal `t`: the
//!   smaller primitive id) names the first winner, but a floating-point test computes the edge
//!   functions of the sheared, rounded ray, so at an exact tie it may find any one winner
//!   (watertightness promises at least one); every winner is the answer there.
//! - How a method's answer is judged against it, with the one tolerance rounding forces, is in
//!   [`verdict`].
//! - For big scenes, [`accel::ExactScene`] gives the same answers faster: a BVH used only to cull
//!   triangles the ray provably cannot meet (slab tests widened by a proven rounding bound).

pub mod accel;
pub mod closest;
pub mod dyadic;
pub mod filter;
pub mod triangle;
pub mod verdict;

pub use accel::ExactScene;
pub use closest::{closest_among, closest_hit, ExactAnswer};
pub use verdict::{judge, Judgement, Tolerance};
