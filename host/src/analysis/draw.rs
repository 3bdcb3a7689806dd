//! `ringpod draw`: a labelled isometric drawing of a ring platform at a pose: the ring, the carriages on it, each
//! chain from its carriage to its platform joint (rods and radial actuators told apart), the platform polygon and
//! the base axes; or the tool carrier's X guide, dyads, frame and tool. Every point drawn comes from the core's
//! inverse kinematics: the carriages from the actuator angles `RingPlatform::inverse` gives, the platform joints
//! from `RingPlatform::joints`; the tool carrier's elbows from `ToolCarrier::inverse`'s `q2`, `q4`.

use std::fmt::Write as _;
use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use ringpod_core::kinematics::{ChainKind, Mechanism, Pose, RingPlatform, ToolCarrier};
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
    /// Per chain: `[shoulder, elbow]` axes of an elbow chain ([`super::placement`]), none for the others.
    pub arms: Vec<Option<[[f64; 3]; 2]>>,
    /// `rod`, `radial` or `elbow` per chain.
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
        let arms = super::placement::place(ring, pose).map_or_else(|| vec![None; chains.len()], |p| p.arms);
        Ok(Self {
            arms,
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
                    ChainKind::Elbow(_) => "elbow",
                })
                .collect(),
            actuators: q.0,
        })
    }

    /// The points whose extent the picture must hold: the ring, the joints and the axes' ends.
    fn extent(&self) -> Vec<[f64; 3]> {
        let mut p: Vec<[f64; 3]> = ring_points(self.ring_radius).collect();
        p.extend(&self.joints);
        p.extend(self.arms.iter().flatten().flatten());
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
        View::fit(&self.extent(), size)
    }
}

impl View {
    /// The view that holds `extent` in a picture of `size`, below the title.
    fn fit(extent: &[[f64; 3]], size: (u32, u32)) -> Self {
        let pts: Vec<(f64, f64)> = extent.iter().map(|p| iso(*p)).collect();
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
    fn paint<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, out: &Path) -> Result<(), plot::PlotError>
    where
        DB::ErrorType: 'static,
    {
        let fail = plot::failed(out);
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
        let legend =
            "ring (grey), carriages B (blue), rods and elbow arms (black), radial actuators (orange), platform joints A (red)";
        // Base axes, with the ring plane's centre O.
        let origin = ground(root, out, &view, [&title, legend], self.axes())?;
        let ring: Vec<(i32, i32)> = ring_points(self.ring_radius).map(|q| view.at(q)).collect();
        root.draw(&PathElement::new(ring, RING.stroke_width(3)))
            .map_err(|e| fail(&e))?;
        // The platform polygon, its joints in chain order.
        outlined(root, out, self.joints.iter().map(|a| view.at(*a)).collect())?;
        // The platform centre.
        let c = [p[0], p[1], p[2]];
        let cp = view.at(c);
        root.draw(&Text::new("O'", (cp.0 + 4, cp.1 + 2), font(13)))
            .map_err(|e| fail(&e))?;
        for (i, ((b, a), kind)) in self.carriages.iter().zip(&self.joints).zip(&self.chains).enumerate() {
            let colour = if *kind == "radial" { RADIAL } else { ROD };
            let (pb, pa) = (view.at(*b), view.at(*a));
            // An elbow chain: carriage to shoulder axis, upper arm, forearm; the others a straight line.
            let path = match self.arms.get(i).copied().flatten() {
                Some([shoulder, elbow]) => vec![pb, view.at(shoulder), view.at(elbow), pa],
                None => vec![pb, pa],
            };
            root.draw(&PathElement::new(path, colour.stroke_width(3)))
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

/// The five-DOF tool carrier at a pose (KINEMATICS.md 2.3), in the base frame (m).
#[derive(Debug, Clone, Serialize)]
pub struct ToolScene {
    pub mechanism: String,
    pub pose: [f64; 6],
    /// The tool point (the pose's position).
    pub tool: [f64; 3],
    /// The frame's corners `p + R (+-a/2, +-b/2, L1)`, `R = Rx(alpha) Ry(beta)`, around the frame.
    pub frame: [[f64; 3]; 4],
    /// The frame pivots `A2`, `A3`: `p + R (0, +-b/2, L1)`.
    pub pivots: [[f64; 3]; 2],
    /// The base pivots `B`, `D` in the dyads' plane `x = q1` (a planar dyad parallel to O-YZ through its frame pivot).
    pub bases: [[f64; 3]; 2],
    /// The elbows: `L2` from each base pivot at IK's angle `q2` (B) or `q4` (D).
    pub elbows: [[f64; 3]; 2],
    /// The actuators IK gives.
    pub actuators: [f64; 6],
}

impl ToolScene {
    /// The scene of the tool carrier at a pose, from its inverse kinematics.
    pub fn of(name: &str, tool: &ToolCarrier<f64>, pose: &Pose<f64>) -> Result<Self, CliError> {
        let q = tool.inverse(pose)?.0;
        let g = tool.geometry();
        let (sa, ca) = pose.alpha.sin_cos();
        let (sb, cb) = pose.beta.sin_cos();
        let p = [pose.x, pose.y, pose.z];
        // R v with R = Rx(alpha) Ry(beta).
        let at = |v: [f64; 3]| {
            let (u, w) = (v[0] * cb + v[2] * sb, -v[0] * sb + v[2] * cb);
            [p[0] + u, p[1] + v[1] * ca - w * sa, p[2] + v[1] * sa + w * ca]
        };
        let (ha, hb, l1) = (g.a / 2.0, g.b / 2.0, g.l1);
        let bases = [g.pivot_b, g.pivot_d].map(|b| [q[0], b[1], b[2]]);
        let elbow = |b: [f64; 3], angle: f64| [b[0], b[1] + g.l2 * angle.cos(), b[2] + g.l2 * angle.sin()];
        Ok(Self {
            mechanism: name.to_owned(),
            pose: pose.to_array(),
            tool: p,
            frame: [
                at([ha, hb, l1]),
                at([-ha, hb, l1]),
                at([-ha, -hb, l1]),
                at([ha, -hb, l1]),
            ],
            pivots: [at([0.0, hb, l1]), at([0.0, -hb, l1])],
            bases,
            elbows: [elbow(bases[0], q[1]), elbow(bases[1], q[3])],
            actuators: q,
        })
    }

    fn centre(&self) -> [f64; 3] {
        let f = &self.frame;
        std::array::from_fn(|k| (f[0][k] + f[2][k]) / 2.0)
    }

    fn axes(&self) -> [(&'static str, [f64; 3]); 3] {
        let r = self.bases[0][1].abs().max(self.bases[1][1].abs()) * 1.2;
        let top = self.frame.iter().map(|c| c[2]).fold(0.0, f64::max);
        [("X", [r, 0.0, 0.0]), ("Y", [0.0, r, 0.0]), ("Z", [0.0, 0.0, top * 1.3])]
    }

    /// The projection of the scene onto the picture's pixels.
    pub fn view(&self, size: (u32, u32)) -> View {
        let mut extent: Vec<[f64; 3]> = self.frame.to_vec();
        extent.extend(self.bases);
        extent.extend(self.elbows);
        extent.push(self.tool);
        extent.extend(self.axes().iter().map(|(_, e)| *e));
        extent.extend(self.rails().iter().flatten());
        View::fit(&extent, size)
    }

    /// The X guide's rails through the base pivots, as long as the frame is wide either way.
    fn rails(&self) -> [[[f64; 3]; 2]; 2] {
        let reach = self.frame.iter().map(|c| c[0].abs()).fold(0.0, f64::max) * 1.5;
        self.bases.map(|b| [[-reach, b[1], b[2]], [reach, b[1], b[2]]])
    }
}

impl Picture for ToolScene {
    fn paint<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, out: &Path) -> Result<(), plot::PlotError>
    where
        DB::ErrorType: 'static,
    {
        let fail = plot::failed(out);
        let view = self.view(root.dim_in_pixel());
        let font = |size: u32| (plot::FONT, size).into_font();
        let p = &self.pose;
        let title = format!(
            "{} at x, y, z = {:.4}, {:.4}, {:.4} m; alpha, beta = {:.2}, {:.2} deg",
            self.mechanism,
            p[0],
            p[1],
            p[2],
            p[3].to_degrees(),
            p[4].to_degrees()
        );
        let legend = "X guide (grey), carriage beam (blue), links L2 and L3 (black), frame (green), tool L1 (orange)";
        ground(root, out, &view, [&title, legend], self.axes())?;
        for rail in self.rails() {
            root.draw(&PathElement::new(
                rail.map(|r| view.at(r)).to_vec(),
                RING.stroke_width(3),
            ))
            .map_err(|e| fail(&e))?;
        }
        let beam = vec![view.at(self.bases[0]), view.at(self.bases[1])];
        root.draw(&PathElement::new(beam, CARRIAGE.stroke_width(3)))
            .map_err(|e| fail(&e))?;
        outlined(root, out, self.frame.iter().map(|c| view.at(*c)).collect())?;
        let (centre, tool) = (view.at(self.centre()), view.at(self.tool));
        root.draw(&PathElement::new(vec![centre, tool], RADIAL.stroke_width(3)))
            .map_err(|e| fail(&e))?;
        root.draw(&Circle::new(tool, 5, RADIAL.filled()))
            .map_err(|e| fail(&e))?;
        root.draw(&Text::new("tool", (tool.0 + 8, tool.1 - 6), font(14)))
            .map_err(|e| fail(&e))?;
        let mid = view.at([self.bases[0][0], 0.0, (self.bases[0][2] + self.bases[1][2]) / 2.0]);
        for (k, (base, pivot)) in [("B", "A2"), ("D", "A3")].into_iter().enumerate() {
            let (b, e, a) = (view.at(self.bases[k]), view.at(self.elbows[k]), view.at(self.pivots[k]));
            root.draw(&PathElement::new(vec![b, e, a], ROD.stroke_width(3)))
                .map_err(|e| fail(&e))?;
            root.draw(&Circle::new(b, 6, CARRIAGE.filled())).map_err(|e| fail(&e))?;
            root.draw(&Circle::new(e, 4, ROD.filled())).map_err(|e| fail(&e))?;
            root.draw(&Circle::new(a, 5, JOINT.filled())).map_err(|e| fail(&e))?;
            root.draw(&Text::new(base, outward(b, mid), font(14)))
                .map_err(|e| fail(&e))?;
            root.draw(&Text::new(pivot, outward(a, centre), font(14)))
                .map_err(|e| fail(&e))?;
        }
        Ok(())
    }
}

/// What both scenes draw first: a white ground, the title and the legend (`text`), and the base axes from the
/// origin O, labelled. Returns the origin's pixel.
fn ground<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    out: &Path,
    view: &View,
    text: [&str; 2],
    axes: [(&'static str, [f64; 3]); 3],
) -> Result<(i32, i32), plot::PlotError>
where
    DB::ErrorType: 'static,
{
    let fail = plot::failed(out);
    let font = |size: u32| (plot::FONT, size).into_font();
    root.fill(&WHITE).map_err(|e| fail(&e))?;
    root.draw(&Text::new(text[0], (16, 12), font(18)))
        .map_err(|e| fail(&e))?;
    root.draw(&Text::new(text[1], (16, 36), font(13)))
        .map_err(|e| fail(&e))?;
    let origin = view.at([0.0; 3]);
    for (name, end) in axes {
        let e = view.at(end);
        root.draw(&PathElement::new(vec![origin, e], RING.mix(0.8).stroke_width(1)))
            .map_err(|e| fail(&e))?;
        root.draw(&Text::new(name, (e.0 + 4, e.1 - 8), font(16)))
            .map_err(|e| fail(&e))?;
    }
    root.draw(&Text::new("O", (origin.0 + 4, origin.1 + 2), font(13)))
        .map_err(|e| fail(&e))?;
    Ok(origin)
}

/// A polygon filled light and outlined: the ring platform, the tool carrier's frame.
fn outlined<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    out: &Path,
    corners: Vec<(i32, i32)>,
) -> Result<(), plot::PlotError>
where
    DB::ErrorType: 'static,
{
    let fail = plot::failed(out);
    root.draw(&Polygon::new(corners.clone(), PLATFORM.mix(0.25)))
        .map_err(|e| fail(&e))?;
    let mut closed = corners.clone();
    closed.extend(corners.first());
    root.draw(&PathElement::new(closed, PLATFORM.stroke_width(2)))
        .map_err(|e| fail(&e))
}

/// Where a label of the point `p` goes: away from `from`, its text's top left corner.
fn outward(p: (i32, i32), from: (i32, i32)) -> (i32, i32) {
    let (dx, dy) = (f64::from(p.0 - from.0), f64::from(p.1 - from.1));
    let len = dx.hypot(dy).max(1e-9);
    let (x, y) = (f64::from(p.0) + 18.0 * dx / len, f64::from(p.1) + 18.0 * dy / len);
    ((x - 9.0).round() as i32, (y - 8.0).round() as i32)
}

/// The pose and the actuators in the units asked for: angles in degrees with `--degrees`.
fn in_units(on: &On, m: &AnyMechanism, pose: [f64; 6], q: [f64; 6]) -> ([f64; 6], [f64; 6]) {
    if !on.degrees {
        return (pose, q);
    }
    let axes = m.axes();
    (
        std::array::from_fn(|i| if i < 3 { pose[i] } else { pose[i].to_degrees() }),
        std::array::from_fn(|i| {
            if axes[i] == ringpod_core::kinematics::AxisKind::Linear {
                q[i]
            } else {
                q[i].to_degrees()
            }
        }),
    )
}

/// Draws the platform at the pose into `--out` and says what it drew.
pub fn run(o: &Options) -> Result<String, CliError> {
    let Selected {
        name, home, mechanism, ..
    } = Selected::of(o.on.mechanism, o.on.geometry)?;
    let pose = pose_arg(&o.on, home, mechanism.characteristic_length(), o.pose, "pose")?;
    let ring = match &mechanism {
        AnyMechanism::Ring(ring) => ring,
        AnyMechanism::Tool(tool) => {
            let scene = ToolScene::of(&name, tool, &pose)?;
            plot::save(o.out, SIZE, &scene)?;
            if o.on.json {
                let mut shown = scene.clone();
                (shown.pose, shown.actuators) = in_units(&o.on, &mechanism, scene.pose, scene.actuators);
                return Ok(serde_json::to_string_pretty(&shown)? + "\n");
            }
            let mut t = format!("{} drawn to {}\n", name, o.out.display());
            for (k, (base, pivot)) in [("B", "A2"), ("D", "A3")].into_iter().enumerate() {
                let (b, a) = (scene.bases[k], scene.pivots[k]);
                let _ = writeln!(
                    t,
                    "  {base} = ({:.4}, {:.4}, {:.4})  {pivot} = ({:.4}, {:.4}, {:.4})",
                    b[0], b[1], b[2], a[0], a[1], a[2]
                );
            }
            let p = scene.tool;
            let _ = writeln!(t, "  tool = ({:.4}, {:.4}, {:.4})", p[0], p[1], p[2]);
            return Ok(t);
        }
    };
    let scene = Scene::of(&name, ring, &pose)?;
    plot::save(o.out, SIZE, &scene)?;
    if o.on.json {
        let mut shown = scene.clone();
        (shown.pose, shown.actuators) = in_units(&o.on, &mechanism, scene.pose, scene.actuators);
        return Ok(serde_json::to_string_pretty(&shown)? + "\n");
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
mod tests;
