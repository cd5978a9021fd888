//! The conformance suite on the CPU backend: every BVH2 method (a-f) and every kd method, closest
//! and any hit, every ray set (primary, shadow, diffuse, uniform, adversarial), on every generated
//! scene and every mesh in `../shared/scenes/`, for BVH2 trees from both builders. Every method's
//! hits must equal the BVH2 stack method's; BVH2 enumerations must equal their reference's, and kd
//! leaf sequences the kd stack traversal's.

mod common;

conformance_suite!(common::check_scene);
