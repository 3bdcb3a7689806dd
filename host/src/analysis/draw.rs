//! `ringpod draw`: a labelled isometric drawing of a ring platform at a pose: the ring, the carriages on it, each
//! chain from its carriage to its platform joint (rods and radial actuators told apart), the platform polygon and
//! the base axes. Every point drawn comes from the core's inverse kinematics: the carriages from the actuator
//! angles `RingPlatform::inverse` gives, the platform joints from `RingPlatform::joints`.

use std::fmt::Write as _;
use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use ringpod_core::kinematics::{ChainKind, Mechanism, Pose, RingPlatform};
use serde::Serialize;

use super::kinematics::{pose_arg, On};
use super::mechanism::{AnyMechanism, Selected};
use crate::error::CliError;
use crate::out::plot::{self, Picture};

/// The picture's size in pixels.
pub const SIZE: (u32, u32) = (900, 760);
const MARGIN: f64 = 50.0;
const TITLE: f64 = 60.0;

/// `draw`: the platform, the pose (the home pose when none) and the picture.
pub struct Options<'a> {
    pub on: On<'a>,
    pub pose: Option<&'a str>,
    pub out: &'a Path,
}

/// What is drawn, in the base frame (m).
#[derive(Debug, Clone, Serialize)]
pub struct Scene {
    pub mechanism: String,
    pub pose: [f64; 6],
    pub ring_radius: f64,
    /// Each chain's carriage on the ring, from its IK angle.
    pub carriages: Vec<[f64; 3]>,
    /// Each chain's platform joint, from IK's joints.
    pub joints: Vec<[f64; 3]>,
    /// `rod` or `radial` per chain.
    pub chains: Vec<&'static str>,
    /// The actuators IK gives (the mechanism's order).
    pub actuators: [f64; 6],
}

impl Scene {
    /// The scene of a ring platform at a pose, from its inverse kinematics.
    pub fn of(name: &str, ring: &RingPlatform<f64>, pose: &Pose<f64>) -> Result<Self, CliError> {
        let q = ring.inverse(pose)?;
        let g = ring.geometry();
        let chains = g.chains();
        let rr = g.ring_radius;
        let joints = ring.joints(pose);
        Ok(Self {
            mechanism: name.to_owned(),
            pose: pose.to_array(),
            ring_radius: rr,
            carriages: (0..chains.len())
                .map(|i| [rr * q.0[i].cos(), rr * q.0[i].sin(), 0.0])
                .collect(),
            joints: joints[..chains.len()].iter().map(|a| [a.x, a.y, a.z]).collect(),
            chains: chains
                .iter()
                .map(|c| match c.kind {
                    ChainKind::Rod(_) => "rod",
                    ChainKind::Radial => "radial",
                })
                .collect(),
            actuators: q.0,
        })
    }

    /// The points whose extent the picture must hold: the ring, the joints and the axes' ends.
    fn extent(&self) -> Vec<[f64; 3]> {
        let mut p: Vec<[f64; 3]> = ring_points(self.ring_radius).collect();
        p.extend(&self.joints);
        p.extend(self.axes().iter().map(|(_, end)| *end));
        p
    }

    /// The base axes: their names and ends.
    fn axes(&self) -> [(&'static str, [f64; 3]); 3] {
        let r = self.ring_radius * 1.3;
        let top = self.joints.iter().map(|a| a[2]).fold(0.0, f64::max);
        [
            ("X", [r, 0.0, 0.0]),
            ("Y", [0.0, r, 0.0]),
            ("Z", [0.0, 0.0, (top * 1.35).max(self.ring_radius * 0.5)]),
        ]
    }

    /// The projection of the scene onto the picture's pixels.
    pub fn view(&self, size: (u32, u32)) -> View {
        let pts: Vec<(f64, f64)> = self.extent().iter().map(|p| iso(*p)).collect();
        let (mut lo, mut hi) = ((f64::MAX, f64::MAX), (f64::MIN, f64::MIN));
        for (u, v) in pts {
            lo = (lo.0.min(u), lo.1.min(v));
            hi = (hi.0.max(u), hi.1.max(v));
        }
        let (w, h) = (f64::from(size.0), f64::from(size.1));
        let scale =
            ((w - 2.0 * MARGIN) / (hi.0 - lo.0).max(1e-9)).min((h - 2.0 * MARGIN - TITLE) / (hi.1 - lo.1).max(1e-9));
        // Centred in the area below the title.
        let (cu, cv) = ((lo.0 + hi.0) / 2.0, (lo.1 + hi.1) / 2.0);
        View {
            scale,
            centre: (cu, cv),
            pixel_centre: (w / 2.0, TITLE + (h - TITLE) / 2.0),
        }
    }
}

/// The ring as a closed polyline.
fn ring_points(rr: f64) -> impl Iterator<Item = [f64; 3]> {
    (0..=120).map(move |k| {
        let t = k as f64 * std::f64::consts::TAU / 120.0;
        [rr * t.cos(), rr * t.sin(), 0.0]
    })
}

/// Isometric projection, seen from (1, 1, 1): X to the lower left, Y to the lower right, Z up (picture units,
/// up positive).
pub fn iso(p: [f64; 3]) -> (f64, f64) {
    let [x, y, z] = p;
    ((y - x) / 2f64.sqrt(), (2.0 * z - x - y) / 6f64.sqrt())
}

/// From the isometric plane to pixels.
#[derive(Debug, Clone, Copy)]
pub struct View {
    scale: f64,
    centre: (f64, f64),
    pixel_centre: (f64, f64),
}

impl View {
    /// The pixel (x right, y down) of a base-frame point.
    pub fn pixel(&self, p: [f64; 3]) -> (f64, f64) {
        let (u, v) = iso(p);
        (
            self.pixel_centre.0 + (u - self.centre.0) * self.scale,
            self.pixel_centre.1 - (v - self.centre.1) * self.scale,
        )
    }

    fn at(&self, p: [f64; 3]) -> (i32, i32) {
        let (x, y) = self.pixel(p);
        (x.round() as i32, y.round() as i32)
    }
}

const RING: RGBColor = RGBColor(120, 120, 120);
const CARRIAGE: RGBColor = RGBColor(31, 90, 180);
const ROD: RGBColor = RGBColor(30, 30, 30);
const RADIAL: RGBColor = RGBColor(220, 110, 0);
const JOINT: RGBColor = RGBColor(200, 30, 30);
const PLATFORM: RGBColor = RGBColor(60, 160, 80);

impl Picture for Scene {
    fn paint<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, out: &Path) -> anyhow::Result<()>
    where
        DB::ErrorType: 'static,
    {
        let fail = plot::failed(out);
        root.fill(&WHITE).map_err(|e| fail(&e))?;
        let view = self.view(root.dim_in_pixel());
        let font = |size: u32| (plot::FONT, size).into_font();
        let p = &self.pose;
        let title = format!(
            "{} at x, y, z = {:.4}, {:.4}, {:.4} m; alpha, beta, gamma = {:.2}, {:.2}, {:.2} deg",
            self.mechanism,
            p[0],
            p[1],
            p[2],
            p[3].to_degrees(),
            p[4].to_degrees(),
            p[5].to_degrees()
        );
        root.draw(&Text::new(title, (16, 12), font(18))).map_err(|e| fail(&e))?;
        let legend =
            "ring (grey), carriages B (blue), rods (black), radial actuators (orange), platform joints A (red)";
        root.draw(&Text::new(legend, (16, 36), font(13)))
            .map_err(|e| fail(&e))?;
        // Base axes, with the ring plane's centre O.
        let origin = view.at([0.0; 3]);
        for (name, end) in self.axes() {
            let e = view.at(end);
            root.draw(&PathElement::new(vec![origin, e], RING.mix(0.8).stroke_width(1)))
                .map_err(|e| fail(&e))?;
            root.draw(&Text::new(name, (e.0 + 4, e.1 - 8), font(16)))
                .map_err(|e| fail(&e))?;
        }
        root.draw(&Text::new("O", (origin.0 + 4, origin.1 + 2), font(13)))
            .map_err(|e| fail(&e))?;
        let ring: Vec<(i32, i32)> = ring_points(self.ring_radius).map(|q| view.at(q)).collect();
        root.draw(&PathElement::new(ring, RING.stroke_width(3)))
            .map_err(|e| fail(&e))?;
        // The platform polygon, its joints in chain order.
        let platform: Vec<(i32, i32)> = self.joints.iter().map(|a| view.at(*a)).collect();
        root.draw(&Polygon::new(platform.clone(), PLATFORM.mix(0.25)))
            .map_err(|e| fail(&e))?;
        let mut closed = platform.clone();
        closed.extend(platform.first());
        root.draw(&PathElement::new(closed, PLATFORM.stroke_width(2)))
            .map_err(|e| fail(&e))?;
        // The platform centre.
        let c = [p[0], p[1], p[2]];
        let cp = view.at(c);
        root.draw(&Text::new("O'", (cp.0 + 4, cp.1 + 2), font(13)))
            .map_err(|e| fail(&e))?;
        for (i, ((b, a), kind)) in self.carriages.iter().zip(&self.joints).zip(&self.chains).enumerate() {
            let colour = if *kind == "radial" { RADIAL } else { ROD };
            let (pb, pa) = (view.at(*b), view.at(*a));
            root.draw(&PathElement::new(vec![pb, pa], colour.stroke_width(3)))
                .map_err(|e| fail(&e))?;
            root.draw(&Circle::new(pb, 6, CARRIAGE.filled()))
                .map_err(|e| fail(&e))?;
            root.draw(&Circle::new(pa, 5, JOINT.filled())).map_err(|e| fail(&e))?;
            root.draw(&Text::new(format!("B{}", i + 1), outward(pb, origin), font(14)))
                .map_err(|e| fail(&e))?;
            root.draw(&Text::new(format!("A{}", i + 1), outward(pa, cp), font(14)))
                .map_err(|e| fail(&e))?;
        }
        Ok(())
    }
}

/// Where a label of the point `p` goes: away from `from`, its text's top left corner.
fn outward(p: (i32, i32), from: (i32, i32)) -> (i32, i32) {
    let (dx, dy) = (f64::from(p.0 - from.0), f64::from(p.1 - from.1));
    let len = dx.hypot(dy).max(1e-9);
    let (x, y) = (f64::from(p.0) + 18.0 * dx / len, f64::from(p.1) + 18.0 * dy / len);
    ((x - 9.0).round() as i32, (y - 8.0).round() as i32)
}

/// Draws the platform at the pose into `--out` and says what it drew.
pub fn run(o: &Options) -> anyhow::Result<String> {
    let Selected {
        name, home, mechanism, ..
    } = Selected::of(o.on.mechanism, o.on.geometry)?;
    let AnyMechanism::Ring(ring) = &mechanism else {
        return Err(CliError::BadNumbers {
            what: "mechanism",
            reason: "draw is for ring platforms (the tool carrier has no ring)".into(),
        }
        .into());
    };
    let pose = pose_arg(&o.on, home, mechanism.characteristic_length(), o.pose, "pose")?;
    let scene = Scene::of(&name, ring, &pose)?;
    plot::save(o.out, SIZE, &scene)?;
    if o.on.json {
        return Ok(serde_json::to_string_pretty(&scene)? + "\n");
    }
    let mut t = String::new();
    let _ = writeln!(t, "{} drawn to {}", name, o.out.display());
    for (i, (b, a)) in scene.carriages.iter().zip(&scene.joints).enumerate() {
        let _ = writeln!(
            t,
            "  chain {} ({:<6}) B{} = ({:.4}, {:.4}, {:.4})  A{} = ({:.4}, {:.4}, {:.4})",
            i + 1,
            scene.chains[i],
            i + 1,
            b[0],
            b[1],
            b[2],
            i + 1,
            a[0],
            a[1],
            a[2]
        );
    }
    Ok(t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use ringpod_core::kinematics::presets;

    /// The centres of the SVG's circles.
    fn circles(svg: &str) -> Vec<(f64, f64)> {
        let attr = |s: &str, name: &str| -> Option<f64> {
            let k = s.find(&format!(" {name}=\""))? + name.len() + 3;
            s[k..].split('"').next()?.parse().ok()
        };
        svg.split("<circle")
            .skip(1)
            .filter_map(|c| Some((attr(c, "cx")?, attr(c, "cy")?)))
            .collect()
    }

    /// The drawing's joints and carriages are where IK puts them: each platform joint `R a + p` (computed here
    /// from the geometry's points) and each carriage `Rr (cos q, sin q, 0)` (from IK's angles) has a circle on
    /// its projected pixel, and nowhere else are circles drawn.
    #[test]
    fn the_drawn_joints_are_iks() {
        for (geometry, pose) in [
            (presets::TRAINER_CH5, [0.1, -0.05, 1.0, 0.05, -0.03, 0.4]),
            (presets::ROTOPOD_CH4, [0.02, 0.0, 0.7, 0.0, 0.04, 1.0]),
        ] {
            let ring = RingPlatform::<f64>::new(&geometry);
            let pose = Pose::from_array(pose);
            let scene = Scene::of("test", &ring, &pose).unwrap();
            let mut svg = String::new();
            {
                let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
                scene.paint(&root, Path::new("test.svg")).unwrap();
                root.present().unwrap();
            }
            let drawn = circles(&svg);
            let view = scene.view(SIZE);
            let q = ring.inverse(&pose).unwrap();
            let r = pose.rotation();
            let n = geometry.chains().len();
            assert_eq!(drawn.len(), 2 * n);
            for (i, c) in geometry.chains().iter().enumerate() {
                let a = r * nalgebra::Vector3::from(c.platform_point) + pose.position();
                let rr = geometry.ring_radius;
                let b = [rr * q.0[i].cos(), rr * q.0[i].sin(), 0.0];
                for p in [[a.x, a.y, a.z], b] {
                    let (x, y) = view.pixel(p);
                    assert!(
                        drawn.iter().any(|d| (d.0 - x).abs() <= 0.5 && (d.1 - y).abs() <= 0.5),
                        "no circle at {p:?} ({x}, {y}): {drawn:?}"
                    );
                }
                assert!((scene.joints[i][0] - a.x).abs() < 1e-12 && (scene.joints[i][2] - a.z).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn isometric_axes() {
        // Seen from (1, 1, 1): X and Y go down and apart, Z straight up, all foreshortened alike.
        let (x, y, z) = (iso([1.0, 0.0, 0.0]), iso([0.0, 1.0, 0.0]), iso([0.0, 0.0, 1.0]));
        assert!(x.0 < 0.0 && x.1 < 0.0 && y.0 > 0.0 && y.1 < 0.0 && z.0 == 0.0 && z.1 > 0.0);
        let len = |p: (f64, f64)| p.0.hypot(p.1);
        assert!((len(x) - len(z)).abs() < 1e-12 && (len(y) - len(z)).abs() < 1e-12);
    }
}
