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

/// The tool carrier's dyads close where IK says: each elbow `L2` from its base pivot at `q2` / `q4`, each
/// frame pivot `L3` from its elbow along `q3` / `q6`, in the plane `x = q1`; the tool `L1` below the frame's
/// centre; and a circle drawn on each frame pivot's pixel.
#[test]
fn the_drawn_tool_carrier_is_iks() {
    let g = presets::TOOL5_EX;
    let tool = ToolCarrier::<f64>::new(&g);
    for pose in [[0.0, 0.0, 0.4, 0.0, 0.0, 0.0], [0.03, -0.02, 0.42, 0.2656, 0.4421, 0.0]] {
        let pose = Pose::from_array(pose);
        let scene = ToolScene::of("test", &tool, &pose).unwrap();
        let q = tool.inverse(&pose).unwrap().0;
        for (k, (drive, link)) in [(1, 2), (3, 5)].into_iter().enumerate() {
            let (b, e, a) = (scene.bases[k], scene.elbows[k], scene.pivots[k]);
            let dist = |u: [f64; 3], v: [f64; 3]| (0..3).map(|i| (u[i] - v[i]).powi(2)).sum::<f64>().sqrt();
            assert!((dist(b, e) - g.l2).abs() < 1e-9);
            assert!((dist(e, a) - g.l3).abs() < 1e-9, "{} vs {}", dist(e, a), g.l3);
            assert!(((e[2] - b[2]).atan2(e[1] - b[1]) - q[drive]).abs() < 1e-9);
            assert!(((a[2] - e[2]).atan2(a[1] - e[1]) - q[link]).abs() < 1e-9);
            assert!((a[0] - q[0]).abs() < 1e-12 && (b[0] - q[0]).abs() < 1e-12);
        }
        let c = scene.centre();
        let to_tool: f64 = (0..3).map(|i| (c[i] - scene.tool[i]).powi(2)).sum::<f64>().sqrt();
        assert!((to_tool - g.l1).abs() < 1e-9);
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
            scene.paint(&root, Path::new("test.svg")).unwrap();
            root.present().unwrap();
        }
        let drawn = circles(&svg);
        let view = scene.view(SIZE);
        for a in scene.pivots {
            let (x, y) = view.pixel(a);
            assert!(drawn.iter().any(|d| (d.0 - x).abs() <= 0.5 && (d.1 - y).abs() <= 0.5));
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
