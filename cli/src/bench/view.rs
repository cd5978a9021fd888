//! Where the bench's camera stands: outside the scene, framing its box (the conformance suite's
//! [`Camera::framing`]), or inside it ([`Camera::inside`]), as in a walk through an interior such
//! as Sponza's atrium or the kitchen.
//!
//! Not every scene has an inside worth a view: from the inside eye of a closed object (the bunny,
//! the dragon, the teapot) every ray hits the back of a triangle. So by default (`--view auto`)
//! the inside view is measured only where its primary rays look like a room's: at least
//! [`ROOM_HITS`] of them hit, and at least [`ROOM_FRONT`] of those hit a triangle's front
//! (counter-clockwise) side. Sponza, the kitchen and the Cornell box pass with 100% and 100%;
//! the bunny, the dragon and the teapot, with 100% hits, show 0% front sides.

use raytrail::core::geometry::Triangle;
use raytrail::core::{Aabb, Hit, Ray};
use raytrail_conformance::rays::Camera;

/// Least share of the inside view's primary rays that hit, for `--view auto` to measure it.
pub const ROOM_HITS: f64 = 0.9;

/// Least share of the inside view's hits on a triangle's front side, for `--view auto`.
pub const ROOM_FRONT: f64 = 0.9;

/// One camera view of a scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    /// From outside the box, framing all of it (the conformance suite's camera).
    Outside,
    /// From inside the box, low, looking along its longer horizontal axis.
    Inside,
}

impl View {
    /// Name in reports.
    pub fn name(self) -> &'static str {
        match self {
            View::Outside => "outside",
            View::Inside => "inside",
        }
    }

    /// The camera of this view of a scene with bounding box `bounds`.
    pub fn camera(self, bounds: Aabb) -> Camera {
        match self {
            View::Outside => Camera::framing(bounds),
            View::Inside => Camera::inside(bounds),
        }
    }

    /// The scene's name as reports show it in this view: the outside view keeps the file name,
    /// the inside view adds " (inside)".
    pub fn label(self, scene: &str) -> String {
        match self {
            View::Outside => scene.to_string(),
            View::Inside => format!("{scene} (inside)"),
        }
    }
}

/// Which views `--view` asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ViewChoice {
    /// Only from outside.
    Outside,
    /// Only from inside.
    Inside,
    /// Both, outside first.
    Both,
    /// Outside, and inside where the inside view looks like a room ([`Enclosure::is_room`]).
    Auto,
}

impl ViewChoice {
    /// Every choice, in the order the usage lists them.
    pub const ALL: [ViewChoice; 4] = [ViewChoice::Outside, ViewChoice::Inside, ViewChoice::Both, ViewChoice::Auto];

    /// The choice without `--view`.
    pub const DEFAULT: ViewChoice = ViewChoice::Auto;

    /// Command-line name.
    pub fn name(self) -> &'static str {
        match self {
            ViewChoice::Outside => "outside",
            ViewChoice::Inside => "inside",
            ViewChoice::Both => "both",
            ViewChoice::Auto => "auto",
        }
    }

    /// The choice of a command-line name.
    pub fn from_name(name: &str) -> Result<ViewChoice, String> {
        Self::ALL.into_iter().find(|c| c.name() == name).ok_or_else(|| {
            format!("--view: unknown view '{name}' (known: {})", Self::ALL.map(ViewChoice::name).join(", "))
        })
    }

    /// The views that may be measured, in order (with [`ViewChoice::Auto`], the inside view only
    /// where [`ViewChoice::keeps`] says so).
    pub fn views(self) -> &'static [View] {
        match self {
            ViewChoice::Outside => &[View::Outside],
            ViewChoice::Inside => &[View::Inside],
            ViewChoice::Both | ViewChoice::Auto => &[View::Outside, View::Inside],
        }
    }

    /// Whether `view`, whose primary rays met `enclosure`, is measured.
    pub fn keeps(self, view: View, enclosure: &Enclosure) -> bool {
        self != ViewChoice::Auto || view == View::Outside || enclosure.is_room()
    }
}

/// What a view's primary rays hit: how much of the image is covered, and by which side of the
/// triangles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Enclosure {
    /// Share of the rays that hit.
    pub hits: f64,
    /// Share of the hits on a triangle's front (counter-clockwise) side.
    pub front: f64,
}

impl Enclosure {
    /// Measures `rays` and their closest `hits` on `triangles`.
    pub fn of(rays: &[Ray], hits: &[Hit], triangles: &[Triangle]) -> Enclosure {
        let (mut hit, mut front) = (0usize, 0usize);
        for (r, h) in rays.iter().zip(hits) {
            let Some(t) = triangles.get(h.prim as usize) else { continue };
            hit += 1;
            front += usize::from((t.v[1] - t.v[0]).cross(t.v[2] - t.v[0]).dot(r.dir()) < 0.0);
        }
        Enclosure { hits: hit as f64 / rays.len().max(1) as f64, front: front as f64 / hit.max(1) as f64 }
    }

    /// Whether this looks like a room seen from within ([`ROOM_HITS`], [`ROOM_FRONT`]).
    pub fn is_room(&self) -> bool {
        self.hits >= ROOM_HITS && self.front >= ROOM_FRONT
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn the_views_cameras_are_the_conformance_suites() {
        let sponza = Aabb::new(Vec3::new(-17.4, -0.9, -7.8), Vec3::new(17.4, 15.6, 7.8));
        assert_eq!(View::Inside.camera(sponza), Camera::inside(sponza));
        // The outside view is the conformance framing, eye outside the box.
        let o = View::Outside.camera(sponza);
        assert_eq!(o, Camera::framing(sponza));
        assert!(o.eye.cmplt(sponza.min).any() || o.eye.cmpgt(sponza.max).any());
    }

    #[test]
    fn choices_and_labels() {
        for c in ViewChoice::ALL {
            assert_eq!(ViewChoice::from_name(c.name()), Ok(c));
        }
        assert!(ViewChoice::from_name("above").unwrap_err().contains("outside, inside, both, auto"));
        assert_eq!(ViewChoice::Both.views(), &[View::Outside, View::Inside]);
        assert_eq!(View::Inside.label("sponza.obj"), "sponza.obj (inside)");
        assert_eq!(View::Outside.label("sponza.obj"), "sponza.obj");
    }

    #[test]
    fn auto_keeps_the_inside_of_rooms_only() {
        // A floor (counter-clockwise from above) and the same floor turned over.
        let (a, b, c) = (Vec3::ZERO, Vec3::X, Vec3::Y);
        let tris = [Triangle::new(a, b, c), Triangle::new(a, c, b)];
        let down = Ray::new(Vec3::new(0.2, 0.2, 1.0), Vec3::NEG_Z, 0.0, f32::INFINITY);
        let hit = |prim| Hit { t: 1.0, prim, u: 0.2, v: 0.2 };
        let room = Enclosure::of(&[down; 10], &[hit(0); 10], &tris);
        assert_eq!(room, Enclosure { hits: 1.0, front: 1.0 });
        let solid = Enclosure::of(&[down; 10], &[hit(1); 10], &tris);
        assert_eq!(solid, Enclosure { hits: 1.0, front: 0.0 });
        let mut open = [hit(0); 10];
        open[..2].fill(Hit::MISS);
        let open = Enclosure::of(&[down; 10], &open, &tris);
        assert_eq!(open, Enclosure { hits: 0.8, front: 1.0 });
        assert!(room.is_room() && !solid.is_room() && !open.is_room());
        for e in [room, solid, open] {
            assert!(ViewChoice::Auto.keeps(View::Outside, &e));
            assert_eq!(ViewChoice::Auto.keeps(View::Inside, &e), e.is_room());
            assert!(ViewChoice::Both.keeps(View::Inside, &e) && ViewChoice::Inside.keeps(View::Inside, &e));
        }
    }
}
