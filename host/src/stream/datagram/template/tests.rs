use super::*;
use proptest::prelude::*;

fn template(text: &str) -> Template {
    Template::parse(text, DEFAULT_RANGES).unwrap_or_else(|e| panic!("{text}: {e}"))
}

fn refusal(text: &str) -> TemplateError {
    Template::parse(text, DEFAULT_RANGES).expect_err(text)
}

/// SimHub's generic serial controller documents an axis value as "127" in Decimal (string) and "7F" in Hex
/// (string) at 8 bits: one step below the middle of 0..255. 0 and 255 are the ends of the range.
#[test]
fn simhub_documented_values() {
    let step = 1.0 / 255.0;
    for (format, middle, top) in [("dec8:<Axis1>", "127", "255"), ("hex8:<Axis1>", "7F", "ff")] {
        let t = template(format);
        let got = t.read(middle.as_bytes()).unwrap();
        assert!((got[0] / 0.050 + step).abs() < 1e-12, "{format}: {got:?}");
        assert_eq!(t.read(top.as_bytes()).unwrap()[0], 0.050);
        assert_eq!(t.read(b"0").unwrap()[0], -0.050);
        assert_eq!(got[1..], [0.0; 5], "the axes the string does not name stay at neutral");
    }
}

/// The Mover and SimTools string of docs.motion4sim.com: `<255><255>`, 24-bit binary axes (0x000000 lowest,
/// 0x7FFFFF middle, 0xFFFFFF highest), `<10><13>`, 28 bytes whole, one axis between filler bytes.
#[test]
fn motion4sim_documented_binary_string() {
    let t = template("bin24:<255><255>aaabbbccc<Axis4a>eeefffggghhh<10><13>");
    let string = |axis: [u8; 3]| {
        let mut s = vec![255, 255];
        s.extend(b"aaabbbccc");
        s.extend(axis);
        s.extend(b"eeefffggghhh\n\r");
        s
    };
    assert_eq!(string([0; 3]).len(), 28);
    let roll = 20f64.to_radians();
    assert_eq!(t.read(&string([0, 0, 0])).unwrap()[3], -roll);
    assert_eq!(t.read(&string([0xff; 3])).unwrap()[3], roll);
    let middle = t.read(&string([0x7f, 0xff, 0xff])).unwrap()[3];
    assert!(middle < 0.0 && middle > -roll * 1e-6, "{middle}");
    // Wrong markers or a short string: refused with the byte where it departs.
    let mut bad = string([0; 3]);
    bad[27] = b'\n';
    assert_eq!(t.read(&bad).unwrap_err(), "byte 15: expected \"eeefffggghhh<10><13>\"");
    assert!(t.read(&string([0; 3])[..13]).unwrap_err().contains("needs 3 bytes"));
}

/// FlyPT Mover's decimal output string: `<123>` is the byte 123, chars are their bytes (`AB<123>` is 65, 66, 123).
#[test]
fn flypt_documented_bytes() {
    let t = template("dec8:AB<123><Axis3a>");
    assert_eq!(t.write([0.0; 6])[..3], [65, 66, 123]);
    assert_eq!(t.read(b"AB{255").unwrap()[2], 0.040);
    assert_eq!(t.read(b"AB<255").unwrap_err(), "byte 1: expected \"AB{\"");
}

/// Every preset reads the string it writes for a drive's pose, and what it writes looks as the front end's
/// settings in the book say.
#[test]
fn presets_read_their_strings() {
    let offsets = [0.010, -0.020, 0.005, 0.1, -0.05, 0.2];
    for (name, _) in PRESETS {
        let t = template(name);
        let got = t.read(&t.write(offsets)).unwrap();
        for k in 0..6 {
            assert!(
                (got[k] - offsets[k]).abs() <= t.quantum()[k] / 2.0 + 1e-12,
                "{name} axis {k}: {got:?}"
            );
        }
    }
    assert_eq!(
        String::from_utf8(template("simtools").write([0.0; 6])).unwrap(),
        "32768~32768~32768~32768~32768~32768~"
    );
    assert_eq!(
        String::from_utf8(template("simhub").write([0.050, 0.0, 0.0, 0.0, 0.0, -1.0])).unwrap(),
        "PFFFF;8000;8000;8000;8000;0\n"
    );
    let flypt = template("flypt").write([0.0; 6]);
    assert_eq!(
        (flypt.len(), &flypt[..2], &flypt[14..]),
        (16, &[255u8, 255][..], &[10u8, 13][..])
    );
    assert_eq!(
        template("SimTools"),
        template("simtools"),
        "a preset's name in any case"
    );
}

/// Each kind of bad template is refused, naming the character where it goes wrong.
#[test]
fn bad_templates_name_the_position() {
    for (text, position, words) in [
        ("nonsense", 1, "neither a preset"),
        ("dec:<Axis1a>", 1, "2 to 32 bits"),
        ("dec33:<Axis1a>", 1, "2 to 32 bits"),
        ("frac12:<Axis1a>", 1, "0 to 9"),
        ("oct8:<Axis1a>", 1, "not an encoding"),
        ("dec8:", 6, "no axis placeholder"),
        ("dec8:A<10>", 10, "no axis placeholder"),
        ("dec8:<Axis1a", 6, "without its `>`"),
        ("dec8:<Axis1a>>", 14, "without its `<`"),
        ("dec8:A<>", 7, "around a byte or an axis"),
        ("dec8:<Ax<is1a>", 6, "around a byte or an axis"),
        ("dec8:<256><Axis1a>", 6, "beyond a byte"),
        ("dec8:<Wind>", 6, "neither a byte"),
        ("dec8:<Axis7a>", 6, "axes are 1 to 6"),
        ("dec8:<Axis0>", 6, "axes are 1 to 6"),
        ("dec8:<Axis1a>,<surge>", 15, "already in the string"),
        ("dec8:<Axis1a><Axis2a>", 14, "need a separator"),
        ("dec8:<Axis1a>0", 14, "read as part of its value"),
        ("dec8:<Axis1a><48>", 14, "read as part of its value"),
        ("hex8:<Axis1a>E", 14, "read as part of its value"),
        ("frac3:<Axis1a>.", 15, "read as part of its value"),
    ] {
        let e = refusal(text);
        assert_eq!(e.position, position, "{text}: {e}");
        assert!(e.reason.contains(words), "{text}: {e}");
        assert!(e
            .to_string()
            .starts_with(&format!("pose format, character {position}: ")));
    }
    // Binary axes are fixed-width: side by side is fine, and so is any byte after them.
    template("bin8:<Axis1a><Axis2a>0");
    template("dec8:<roll>,<PITCH>;<Yaw>");
}

/// Strings that depart from the template are refused, each with the byte where and why.
#[test]
fn bad_strings_are_refused() {
    let t = template("dec10:S<Axis1a>,<Axis2a>E");
    assert_eq!(t.read(b"S1023,0E").unwrap()[..2], [0.050, -0.050]);
    for (string, words) in [
        (
            &b"S1024,0E"[..],
            "byte 2: surge value 1024 is beyond the bit range's 1023",
        ),
        (b"S,0E", "byte 2: surge value has no digits"),
        (b"X1,0E", "byte 1: expected \"S\""),
        (b"S1,0E\n", "byte 6: 1 bytes after the string's end"),
        (b"S1;0E", "byte 3: expected \",\""),
        (b"S99999999999,0E", "beyond 32 bits"),
    ] {
        let e = t.read(string).unwrap_err();
        assert!(e.contains(words), "{}: {e}", String::from_utf8_lossy(string));
    }
    let t = template("frac3:<Axis6a>;");
    assert_eq!(t.read(b"-1.000;").unwrap()[5], -20f64.to_radians());
    assert!(t.read(b"1.5;").unwrap_err().contains("beyond -1..1"));
    assert!(t.read(b"-;").unwrap_err().contains("not a decimal fraction"));
}

#[test]
fn ranges_are_six_positive_numbers() {
    assert_eq!(
        parse_ranges("100,100,50,15,15,30").unwrap(),
        [100.0, 100.0, 50.0, 15.0, 15.0, 30.0]
    );
    assert!(parse_ranges("1,2,3").unwrap_err().contains("expected 6 ranges"));
    assert!(parse_ranges("1,2,3,4,5,0")
        .unwrap_err()
        .contains("yaw range must be above 0"));
    let t = Template::parse("dec8:<Axis1a>", [100.0, 1.0, 1.0, 1.0, 1.0, 1.0]).unwrap();
    assert_eq!(t.read(b"255").unwrap()[0], 0.100, "a range given in mm reads in m");
}

fn encodings() -> impl Strategy<Value = String> {
    prop_oneof![
        (2u8..=32).prop_map(|b| format!("dec{b}")),
        (2u8..=32).prop_map(|b| format!("hex{b}")),
        (2u8..=32).prop_map(|b| format!("bin{b}")),
        (0u8..=9).prop_map(|p| format!("frac{p}")),
    ]
}

proptest! {
    /// A template formats a pose and reads it back within half its quantum (a pose beyond the range comes back at
    /// its end).
    #[test]
    fn round_trip_within_the_quantum(
        encoding in encodings(),
        separator in prop::sample::select(vec!["~", ",", ";", "<10>", " | "]),
        order in Just([0usize, 1, 2, 3, 4, 5]).prop_shuffle(),
        fractions in prop::array::uniform6(-1.2f64..1.2),
    ) {
        let names = order.map(|k| format!("<Axis{}a>", k + 1));
        let text = format!("{encoding}:<255>{}<10>", names.join(separator));
        let t = template(&text);
        let ranges = ranges_si(DEFAULT_RANGES);
        let offsets: [f64; 6] = core::array::from_fn(|k| fractions[k] * ranges[k]);
        let got = t.read(&t.write(offsets)).unwrap();
        for k in 0..6 {
            let want = offsets[k].clamp(-ranges[k], ranges[k]);
            prop_assert!((got[k] - want).abs() <= t.quantum()[k] / 2.0 + 1e-12, "{text} axis {k}: {got:?} vs {want}");
        }
    }
}
