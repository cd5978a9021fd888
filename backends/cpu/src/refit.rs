//! A prepared scene refitted to moved vertices ([`PreparedScene::refit`]) on the backend's
//! threads.

use crate::stream::Rayon;
use crate::CpuBackend;
use raytrail_core::prepared::PreparedScene;
use raytrail_core::scene::Scene;
use raytrail_core::Error;

impl CpuBackend {
    /// [`PreparedScene::refit`] of `prepared` to `moved`, its passes over the leaves, the wide
    /// trees' nodes and their triangles on this backend's threads
    /// ([`PreparedScene::refit_with`]); the result is the serial refit's bit for bit.
    pub fn refit(&self, prepared: &mut PreparedScene, moved: &Scene) -> Result<(), Error> {
        self.install(|| prepared.refit_with(moved, &Rayon))
    }
}

#[cfg(test)]
mod tests {
    use crate::CpuBackend;
    use raytrail_conformance::scenes::{breathing, sphereflake};
    use raytrail_core::bvh2::SahBuilder;
    use raytrail_core::method::Method;
    use raytrail_core::prepared::PreparedScene;
    use raytrail_core::wide::WideBvh;

    /// Every part the refit writes, NaN gaps included, as text: equal text is equal bits.
    fn parts(p: &PreparedScene) -> String {
        fn wide<const W: usize>(t: &Option<WideBvh<W>>) -> String {
            format!("{:?}", t.as_ref().map(|t| (t.nodes(), t.triangles(), t.blocks())))
        }
        let trees = [wide(&p.wide4), wide(&p.wide4_naive), wide(&p.wide8), wide(&p.wide8_sah)];
        format!("{:?} {trees:?}", p.bvh.nodes())
    }

    /// The backend's refit on two threads (leaves, nodes and triangles in pieces of 4096 over
    /// tasks) writes what the serial refit writes, on a scene of several pieces.
    #[test]
    fn the_parallel_refit_is_the_serial_one_bit_for_bit() {
        let scene = sphereflake(3);
        let bvh = SahBuilder::default().build(scene.triangles()).unwrap();
        let mut serial = PreparedScene::new(&scene, bvh, &Method::ALL).unwrap();
        let mut parallel = serial.clone();
        let backend = CpuBackend::with_threads(2).unwrap();
        for phase in [0.7, 2.1] {
            let moved = breathing(&scene, phase).unwrap();
            serial.refit(&moved).unwrap();
            backend.refit(&mut parallel, &moved).unwrap();
            assert_eq!(parts(&serial), parts(&parallel), "phase {phase}");
        }
        let pieces = serial.bvh.nodes().len() / 4096;
        assert!(pieces >= 2, "{} nodes: one piece would show little", serial.bvh.nodes().len());
    }
}
