use super::*;
use proptest::prelude::*;
use ringpod_core::kinematics::presets::{self, Preset};
use ringpod_core::kinematics::{Mechanism, NewtonOptions, RingPlatform, FROM_HOME_DISTANCE};

/// Uniform numbers in [-1, 1) from a fixed seed (an LCG: the same on every run).
fn uniform(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

fn trainer_file() -> RigFile {
    RigFile::of(
        &presets::TRAINER_MODEL,
        Preset::TrainerModel.home(),
        Some(presets::TRAINER_MODEL_RANGES),
        drives::of_preset(Preset::TrainerModel),
    )
}

#[test]
fn a_rig_file_round_trips_exactly() {
    let file = trainer_file();
    let text = file.to_toml().unwrap();
    let back: RigFile = toml::from_str(&text).unwrap();
    assert_eq!(back, file);
    assert_eq!(back.to_toml().unwrap(), text);
}

#[test]
fn a_rig_restating_the_preset_drives_bit_identical_ik() {
    let rig = parse(&trainer_file().to_toml().unwrap())
        .and_then(|f| f.check())
        .unwrap();
    let (ours, preset) = (
        RingPlatform::<f64>::new(&rig.geometry),
        RingPlatform::<f64>::new(&presets::TRAINER_MODEL),
    );
    let (ours32, preset32) = (
        RingPlatform::<f32>::new(&rig.geometry),
        RingPlatform::<f32>::new(&presets::TRAINER_MODEL),
    );
    let mut uniform = uniform(5);
    for _ in 0..2_000 {
        let p = Pose::new(
            uniform() * 0.06,
            uniform() * 0.06,
            0.227 + uniform() * 0.05,
            uniform() * 0.4,
            uniform() * 0.4,
            uniform() * 4.0,
        );
        assert_eq!(ours.inverse(&p), preset.inverse(&p));
        assert_eq!(ours32.inverse(&p.cast()), preset32.inverse(&p.cast()));
    }
    assert_eq!(rig.home, Pose::from_array(Preset::TrainerModel.home()));
    assert_eq!(rig.ranges, Some(presets::TRAINER_MODEL_RANGES));
}

/// Each class of mistake, and the key its error names.
#[test]
fn every_invalid_class_names_its_key() {
    type Mistake = Box<dyn Fn(&mut RigFile)>;
    let cases: Vec<(&str, Mistake)> = vec![
        ("name", Box::new(|f| f.name.clear())),
        ("ring_radius", Box::new(|f| f.ring_radius = -0.2)),
        ("ring_radius", Box::new(|f| f.ring_radius = f64::NAN)),
        ("rod_length", Box::new(|f| f.rod_length = 0.0)),
        ("home", Box::new(|f| f.home[5] = f64::INFINITY)),
        ("home", Box::new(|f| f.home[2] = 0.9)),
        ("home", Box::new(|f| f.home[1] = 0.1)),
        ("chains", Box::new(|f| f.chains.truncate(2))),
        (
            "chains",
            Box::new(|f| {
                f.chains[0].kind = KindSpec::Radial;
                f.chains[0].branch = None;
            }),
        ),
        ("chains[0].branch", Box::new(|f| f.chains[0].kind = KindSpec::Radial)),
        ("chains[0].branch", Box::new(|f| f.chains[0].branch = None)),
        (
            "chains[2].branch",
            Box::new(|f| f.chains[2].branch = Some(BranchSpec::Plus)),
        ),
        (
            "chains[1].platform_point",
            Box::new(|f| f.chains[1].platform_point = f.chains[0].platform_point),
        ),
        (
            "chains[3].platform_point",
            Box::new(|f| f.chains[3].platform_point[0] = f64::NAN),
        ),
        ("limits.stroke", Box::new(|f| f.limits.stroke = None)),
        ("limits.stroke", Box::new(|f| f.limits.stroke = Some([0.3, 0.2]))),
        (
            "limits.carriage_spacing_deg",
            Box::new(|f| f.limits.carriage_spacing_deg = [120.0, 12.0]),
        ),
        ("limits.base_cone_deg", Box::new(|f| f.limits.base_cone_deg = 95.0)),
        (
            "limits.platform_cone_deg",
            Box::new(|f| f.limits.platform_cone_deg = -1.0),
        ),
        (
            "limits.min_singularity_index",
            Box::new(|f| f.limits.min_singularity_index = 1.5),
        ),
        (
            "limits.centre_of_mass",
            Box::new(|f| f.limits.centre_of_mass[2] = f64::NAN),
        ),
        ("spec.heave", Box::new(|f| f.spec.as_mut().unwrap().heave = -0.01)),
    ];
    for (key, break_it) in cases {
        let mut f = trainer_file();
        break_it(&mut f);
        let e = f.check().expect_err(key);
        assert_eq!(e.key, key, "{e}");
        assert!(!e.why.is_empty());
    }
    // Syntax and unknown keys: toml's message with the line.
    let e = parse("name = \"x\"\nring_radius = 0.3\nrod_lenght = 0.2\n").unwrap_err();
    assert!(e.why.contains("rod_lenght") && e.why.contains("line 3"), "{e}");
}

/// A rig file with elbow chains as a builder writes it (the book's example in Rig files): the trainer model's rods and
/// two arms of ch. 5.1 fig. 5.2.
const ELBOW_RIG: &str = r#"
name = "my-elbow-rig"
ring_radius = 0.286
rod_length = 0.312
home = [0, 0, 0.227, 0, 0, 0]

[[chains]]
kind = "rod"
branch = "plus"
platform_point = [-0.194, -0.031, 0]

[[chains]]
kind = "rod"
branch = "minus"
platform_point = [0.194, -0.031, 0]

[[chains]]
kind = "elbow"
shoulder_radius = 0.258
shoulder_height = 0.017
upper_arm = 0.105
forearm = 0.189
elbow = "up"
platform_point = [0.181, 0.160, 0]

[[chains]]
kind = "elbow"
shoulder_radius = 0.258
shoulder_height = 0.017
upper_arm = 0.105
forearm = 0.189
elbow = "up"
platform_point = [-0.181, 0.160, 0]

[limits]
shoulder_angle_deg = [100, 190]
elbow_angle_deg = [25, 155]
min_singularity_index = 0.02
centre_of_mass = [0, 0, 0.02]
"#;

#[test]
fn a_rig_file_with_elbow_chains_drives_the_preset_s_ik() {
    let rig = parse(ELBOW_RIG).and_then(|f| f.check()).unwrap();
    let m = RingPlatform::<f64>::new(&rig.geometry);
    let preset = RingPlatform::<f64>::new(&presets::TRAINER_ELBOW);
    assert_eq!(m.axes(), preset.axes());
    let mut uniform = uniform(9);
    for _ in 0..1_000 {
        let p = Pose::new(
            uniform() * 0.05,
            uniform() * 0.05,
            0.227 + uniform() * 0.04,
            uniform() * 0.3,
            uniform() * 0.3,
            uniform() * 4.0,
        );
        assert_eq!(m.inverse(&p), preset.inverse(&p));
    }
    // The preset's own file round-trips and restates the preset exactly.
    let file = RigFile::of(
        &presets::TRAINER_ELBOW,
        Preset::TrainerElbow.home(),
        Preset::TrainerElbow.spec_ranges(),
        drives::of_preset(Preset::TrainerElbow),
    );
    let text = file.to_toml().unwrap();
    let back = parse(&text).unwrap();
    assert_eq!(back, file);
    let rig = back.check().unwrap();
    let mut renamed = rig.geometry;
    renamed.name = presets::TRAINER_ELBOW.name;
    assert_eq!(renamed, presets::TRAINER_ELBOW);
    assert_eq!(rig.record.geometry().unwrap(), presets::TRAINER_ELBOW);
}

/// Each mistake in an elbow chain or its limits, and the key its error names.
#[test]
fn every_invalid_elbow_key_is_named() {
    type Mistake = Box<dyn Fn(&mut RigFile)>;
    let cases: Vec<(&str, Mistake)> = vec![
        (
            "chains[2].shoulder_radius",
            Box::new(|f| f.chains[2].shoulder_radius = None),
        ),
        (
            "chains[2].shoulder_radius",
            Box::new(|f| f.chains[2].shoulder_radius = Some(0.0)),
        ),
        (
            "chains[3].shoulder_height",
            Box::new(|f| f.chains[3].shoulder_height = None),
        ),
        (
            "chains[3].shoulder_height",
            Box::new(|f| f.chains[3].shoulder_height = Some(f64::INFINITY)),
        ),
        ("chains[2].upper_arm", Box::new(|f| f.chains[2].upper_arm = Some(-0.1))),
        ("chains[2].upper_arm", Box::new(|f| f.chains[2].upper_arm = None)),
        ("chains[3].forearm", Box::new(|f| f.chains[3].forearm = Some(f64::NAN))),
        ("chains[2].elbow", Box::new(|f| f.chains[2].elbow = None)),
        (
            "chains[2].branch",
            Box::new(|f| f.chains[2].branch = Some(BranchSpec::Plus)),
        ),
        ("chains[0].upper_arm", Box::new(|f| f.chains[0].upper_arm = Some(0.1))),
        (
            "chains[1].elbow",
            Box::new(|f| f.chains[1].elbow = Some(ElbowSpec::Down)),
        ),
        (
            "chains[2].shoulder_radius",
            Box::new(|f| {
                f.chains[2].kind = KindSpec::Radial;
                f.limits.stroke = Some([0.1, 0.3]);
            }),
        ),
        (
            "limits.shoulder_angle_deg",
            Box::new(|f| f.limits.shoulder_angle_deg = None),
        ),
        (
            "limits.shoulder_angle_deg",
            Box::new(|f| f.limits.shoulder_angle_deg = Some([190.0, 100.0])),
        ),
        (
            "limits.shoulder_angle_deg",
            Box::new(|f| f.limits.shoulder_angle_deg = Some([0.0, f64::NAN])),
        ),
        (
            "limits.elbow_angle_deg",
            Box::new(|f| f.limits.elbow_angle_deg = Some([0.0, 200.0])),
        ),
        (
            "limits.elbow_angle_deg",
            Box::new(|f| f.limits.elbow_angle_deg = Some([90.0, 90.0])),
        ),
        // Arms too short for the home pose, or the home pose outside the shoulders' travel.
        (
            "home",
            Box::new(|f| {
                f.chains[2].upper_arm = Some(0.05);
                f.chains[2].forearm = Some(0.05);
            }),
        ),
        ("home", Box::new(|f| f.limits.shoulder_angle_deg = Some([160.0, 190.0]))),
        (
            "chains",
            Box::new(|f| {
                let mut extra = f.chains[2].clone();
                extra.platform_point = [0.0, -0.2, 0.0];
                f.chains.push(extra);
            }),
        ),
    ];
    for (key, break_it) in cases {
        let mut f = parse(ELBOW_RIG).unwrap();
        break_it(&mut f);
        let e = f.check().expect_err(key);
        assert_eq!(e.key, key, "{e}");
        assert!(!e.why.is_empty());
    }
    // A value or a key toml cannot take: its message names it and the line.
    let line_of = |what: &str| ELBOW_RIG[..ELBOW_RIG.find(what).unwrap()].matches('\n').count() + 1;
    let e = parse(&ELBOW_RIG.replacen("elbow = \"up\"", "elbow = \"sideways\"", 1)).unwrap_err();
    let line = format!("line {}", line_of("elbow = \"up\""));
    assert!(e.why.contains("sideways") && e.why.contains(&line), "{e}");
    let e = parse(&ELBOW_RIG.replacen("forearm = 0.189", "fore_arm = 0.189", 1)).unwrap_err();
    let line = format!("line {}", line_of("forearm = 0.189"));
    assert!(e.why.contains("fore_arm") && e.why.contains(&line), "{e}");
}

fn perturbed(factors: [f64; 10]) -> RigFile {
    let mut f = trainer_file();
    f.ring_radius *= factors[0];
    f.rod_length *= factors[1];
    for (i, c) in f.chains.iter_mut().enumerate() {
        c.platform_point[0] *= factors[2 + 2 * i];
        c.platform_point[1] *= factors[3 + 2 * i];
    }
    f
}

/// The random rigs below are not vacuous: most of them are valid and inside the checks at the tested poses.
#[test]
fn most_perturbed_rigs_are_valid() {
    let mut uniform = uniform(17);
    let valid = (0..200)
        .filter(|_| {
            perturbed(core::array::from_fn(|_| 1.0 + 0.05 * uniform()))
                .check()
                .is_ok()
        })
        .count();
    assert!(valid > 100, "{valid} of 200 valid");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    /// Rigs no preset describes (the model's dimensions each changed by up to 5 %): every one that is valid
    /// passes IK -> FK round trips from no guess at poses inside its checks.
    #[test]
    fn random_valid_rigs_round_trip(factors in prop::array::uniform10(0.95..1.05f64), offsets in prop::array::uniform6(-1.0..1.0f64)) {
        let Ok(rig) = perturbed(factors).check() else { return Ok(()) };
        let m = RingPlatform::<f64>::new(&rig.geometry);
        let h = rig.home.to_array();
        let p = Pose::new(h[0] + offsets[0] * 0.03, h[1] + offsets[1] * 0.03, h[2] + offsets[2] * 0.02,
            offsets[3] * 0.15, offsets[4] * 0.15, offsets[5] * 3.0);
        let Ok((q, report)) = m.inverse_checked(&p) else { return Ok(()) };
        if !report.all_pass() {
            return Ok(());
        }
        let options = NewtonOptions { max_distance: FROM_HOME_DISTANCE, ..NewtonOptions::default() };
        let start = ringpod_core::kinematics::start_from_home(&m, &q, &rig.home);
        match m.forward(&q, &start, &options) {
            Ok(fk) => {
                let (a, b) = (fk.pose.to_array(), p.to_array());
                prop_assert!((0..5).all(|i| (a[i] - b[i]).abs() < 1e-9), "{:?} vs {:?}", fk.pose, p);
            }
            // Refusing near a type-2 singularity is right; anything else is not.
            Err(e) => prop_assert_eq!(e, ringpod_core::kinematics::KinematicsError::NearSingularity),
        }
    }
}

/// A list longer than its key takes is refused at that key (serde would read the first elements and drop the rest),
/// reading no further than one element past the length.
#[test]
fn lists_of_the_wrong_length_are_refused_by_key() {
    let text = trainer_file().to_toml().unwrap();
    let home = text.lines().find(|l| l.starts_with("home = ")).unwrap().to_owned();
    let seven = parse(&text.replace(&home, "home = [0, 0, 0.227, 0, 0, 0, 1]")).unwrap_err();
    assert_eq!(seven.key, "home", "{seven}");
    assert!(seven.why.contains("more than 6"), "{seven}");
    let five = parse(&text.replace(&home, "home = [0, 0, 0.227, 0, 0]")).unwrap_err();
    assert_eq!(five.key, "home", "{five}");
    let point = text
        .lines()
        .find(|l| l.starts_with("platform_point = "))
        .unwrap()
        .to_owned();
    let huge = format!("platform_point = [{}]", vec!["0.1"; 100_000].join(", "));
    let e = parse(&text.replacen(&point, &huge, 1)).unwrap_err();
    assert_eq!(e.key, "platform_point", "{e}");
    assert!(e.why.contains("more than 3"), "{e}");
    let e = parse(&text.replace("stroke = [", "stroke = [0.2, ")).unwrap_err();
    assert_eq!(e.key, "stroke", "{e}");
}

/// A name is printed on lines of its own: a line break or a control character is refused by key.
#[test]
fn a_name_with_control_characters_is_refused() {
    for name in ["a\nb", "tab\there", "bell\u{7}", "\r"] {
        let mut f = trainer_file();
        f.name = name.into();
        let e = f.check().unwrap_err();
        assert_eq!(e.key, "name", "{name:?}: {e}");
    }
    let mut f = trainer_file();
    f.name = "my rig (ü)".into();
    assert!(f.check().is_ok());
}

/// Keys of chains the rig does not have: a stroke without radial chains, arm limits without elbow chains.
#[test]
fn limits_of_chains_the_rig_has_not_are_refused_by_key() {
    let mut f = trainer_file();
    let r = 0.1;
    f.chains = (0..6)
        .map(|i| {
            let a = std::f64::consts::TAU * f64::from(i) / 6.0 + 0.3;
            let mut c = f.chains[0].clone();
            c.branch = Some(if i % 2 == 0 {
                BranchSpec::Plus
            } else {
                BranchSpec::Minus
            });
            c.platform_point = [r * a.cos(), r * a.sin(), 0.0];
            c
        })
        .collect();
    assert!(f.chains.iter().all(|c| c.kind == KindSpec::Rod));
    let e = f.check().unwrap_err();
    assert_eq!(e.key, "limits.stroke", "{e}");
    let mut f = trainer_file();
    f.limits.shoulder_angle_deg = Some([100.0, 190.0]);
    assert_eq!(f.check().unwrap_err().key, "limits.shoulder_angle_deg");
    let mut f = trainer_file();
    f.limits.elbow_angle_deg = Some([25.0, 155.0]);
    assert_eq!(f.check().unwrap_err().key, "limits.elbow_angle_deg");
}

/// `rig check`'s "drivable" homes the rig in the simulated machine: the trainer model homes within the bound; a
/// home yaw of 1e6 or 1e10 rad is out of range before it is homed, a pose velocity of 1e-30 ends in a move that
/// never ends. Each is seen in well under a second of the check's time.
#[test]
fn a_rig_that_cannot_home_is_not_drivable() {
    let rig = trainer_file().check().unwrap();
    let t = homing::homing_time(&rig.record).unwrap();
    assert!(t > 0.5 && t < homing::HOMING_LIMIT_S, "{t}");
    for yaw in [1e6, 1e10] {
        let mut f = trainer_file();
        f.home[5] = yaw;
        let e = f.check().unwrap_err();
        assert_eq!(e.key, "home", "{yaw}: {e}");
        assert!(e.why.contains("out of range"), "{yaw}: {e}");
    }
    let mut f = trainer_file().with_sections(&rig.record);
    if let Some(m) = &mut f.motion {
        m.pose_velocity = [1e-30; 6];
    }
    let rig = f.check().unwrap();
    let started = std::time::Instant::now();
    let e = homing::homing_time(&rig.record).unwrap_err();
    assert!(e.contains("stalls"), "{e}");
    assert!(started.elapsed() < std::time::Duration::from_secs(20));
}

/// A home of finite numbers far beyond any pose is out of range, by key and value, not "NaN or infinite" (which
/// the kinematics, overflowing on it, would say).
#[test]
fn a_home_far_out_of_range_is_said_to_be_out_of_range() {
    let text = trainer_file().to_toml().unwrap();
    let home = text.lines().find(|l| l.starts_with("home = ")).unwrap().to_owned();
    for (bad, says) in [
        ("home = [0, 0, 0.227, 0, 0, 1e300]", "gamma = 1e300 rad is out of range"),
        ("home = [1e300, 0, 0.227, 0, 0, 0]", "x = 1e300 m is out of range"),
        ("home = [0, 0, 0.227, 7, 0, 0]", "alpha = 7 rad is out of range"),
    ] {
        let e = parse(&text.replace(&home, bad))
            .and_then(|f| f.check().map(|_| ()))
            .unwrap_err();
        assert_eq!(e.key, "home", "{bad}: {e}");
        assert!(e.why.contains(says) && !e.why.contains("NaN"), "{bad}: {e}");
    }
}

/// `[[spare]]` in a rig file: the spare axes' section, none fitted without it; a fitted axis with the supply senses
/// on, a third axis and a value out of range are refused by their keys.
#[test]
fn spare_axes_in_a_rig_file_are_checked_with_the_pins_they_take() {
    use ringpod_core::motion::SpareAxisSettings;
    use ringpod_core::protocol::Settings;
    let file = trainer_file();
    let record = file.check().unwrap().record;
    assert_eq!(
        file.spare_section(&record).unwrap(),
        Settings::Spare([SpareAxisSettings::NONE; 2])
    );
    let spare = "\n[[spare]]\nenabled = true\nsteps_per_unit = 400.0\nvelocity = 20.0\nacceleration = 200.0\n\
                 travel = [-5.0, 120.0]\n";
    let text = file.to_toml().unwrap() + spare;
    let with = parse(&text).unwrap();
    let e = with.spare_section(&record).unwrap_err().to_string();
    assert!(e.contains("spare[0].enabled") && e.contains("senses"), "{e}");
    let mut unsensed = with.clone();
    let mut supervisor = unsensed.supervisor.unwrap_or_default();
    supervisor.logic_sense = false;
    supervisor.power_sense = false;
    unsensed.supervisor = Some(supervisor);
    let record = unsensed.check().unwrap().record;
    let Settings::Spare(axes) = unsensed.spare_section(&record).unwrap() else {
        panic!("the spare section")
    };
    assert_eq!(
        (axes[0].steps_per_unit, axes[0].travel, axes[1]),
        (400.0, [-5.0, 120.0], SpareAxisSettings::NONE)
    );
    let back: RigFile = toml::from_str(&unsensed.to_toml().unwrap()).unwrap();
    assert_eq!(back, unsensed, "round trips");
    let mut fast = unsensed.clone();
    fast.spare[0].velocity = 1_000.0;
    let e = fast.spare_section(&record).unwrap_err().to_string();
    assert!(e.contains("spare[0].velocity"), "{e}");
    let mut three = unsensed;
    three.spare = vec![three.spare[0]; 3];
    assert!(three
        .spare_section(&record)
        .unwrap_err()
        .to_string()
        .contains("at most two"));
}
