//! Two corners of a real Project CARS drive, read through the AMS2 layout.
//!
//! Source: Python_UDP_Receiver (vthinsel, CC0 1.0 Universal, `github.com/vthinsel/Python_UDP_Receiver`, commit
//! 7483eb5), `pcars.bin`: Project CARS's UDP telemetry as the game sent it (build 1200, an Audi A1 quattro at
//! Dubai Autodrome), each `sTelemetryData` packet of 1,367 bytes with its arrival time. Its records 2657 to 2666 (a
//! left-hand corner at 26 m/s) and 1651 to 1660 (a right-hand corner at 29 m/s, braking at its end), the fields
//! that Project CARS's shared memory and AMS2's `$pcars2$` hold alike, as the game sent them.

use super::super::super::G;
use super::super::testing::Page;
use super::decode;
use super::tests::shared_memory;
use crate::games::gravity_from_attitude;

/// One packet: `sCurrentTime` (s), `sSpeed` (m/s), `sOrientation[3]`, `sAngularVelocity[3]`,
/// `sLocalAcceleration[3]`, `sTyreRPS[4]` (FL, FR, RL, RR; negative rolling forwards).
type Packet = [f32; 15];

#[rustfmt::skip]
const LEFT: [Packet; 10] = [
    [79.79999, 26.155733, 0.03468338, 0.41109756, -0.036360335, -0.01366496, 0.4226485, -0.046264697, 9.388546, 0.85216653, 1.2242998, -84.8344, -86.75552, -85.32962, -87.06944],
    [79.84, 26.159754, 0.034045856, 0.393273, -0.035033524, 0.0010456993, 0.4466809, -0.049759813, 9.82657, 1.2536466, -0.38380066, -86.226135, -87.80155, -86.59175, -88.03012],
    [79.880005, 26.155624, 0.033646163, 0.37389138, -0.034365468, -0.006884748, 0.48004174, -0.035703037, 10.187378, 1.061138, -0.5639579, -86.359276, -87.71579, -86.97296, -88.0488],
    [79.899994, 26.123154, 0.03331707, 0.36373773, -0.03415895, -0.001957336, 0.50689185, -0.029091544, 10.767894, 0.8959642, 1.1801984, -84.73338, -86.68601, -85.457756, -87.26314],
    [79.94, 26.104519, 0.03266037, 0.3423697, -0.0332481, -0.0016366804, 0.53607357, -0.042362325, 10.88684, 0.8009904, 0.06614782, -85.74307, -87.60516, -86.687096, -88.04585],
    [79.97998, 26.087662, 0.03248962, 0.31943807, -0.032813236, -0.014418887, 0.56807446, -0.030932574, 11.255751, 0.8491863, -0.26662365, -86.241234, -87.58278, -87.43703, -88.131325],
    [80.0, 26.05429, 0.032308433, 0.30757844, -0.032696854, -0.011357783, 0.5921371, -0.02654168, 11.680074, 0.5723211, 1.0605564, -84.65338, -86.50508, -85.82556, -87.37878],
    [80.04001, 26.025864, 0.03172867, 0.28322816, -0.032657895, -0.0054677096, 0.61007655, -0.02153438, 11.379831, 0.13656433, 0.19682127, -85.796295, -87.25449, -86.99666, -88.01354],
    [80.07999, 25.994879, 0.030594856, 0.25841072, -0.034000568, 0.004111181, 0.62073517, 0.013047519, 11.623766, 0.04615656, -0.07426958, -86.46901, -86.86241, -87.323364, -87.74641],
    [80.100006, 25.96165, 0.029623654, 0.24597526, -0.03446798, 0.024796933, 0.62400067, 0.0031399187, 12.1251745, 0.06684375, 0.8390604, -84.89263, -86.0922, -86.0306, -87.217636],
];

#[rustfmt::skip]
const RIGHT: [Packet; 10] = [
    [46.299988, 28.99464, -0.0016837275, -2.3086052, -0.053400505, 0.039083716, -0.4914368, 0.024269724, -11.394, -0.73012024, 1.890301, -93.43788, -90.574875, -95.38031, -90.89522],
    [46.339996, 28.868242, -0.0019202771, -2.2881944, -0.05475987, 0.03367268, -0.5096055, 0.034503378, -11.622047, -0.53220546, 1.8884683, -93.07933, -90.26511, -95.062325, -90.26686],
    [46.380005, 28.739538, -0.0015022464, -2.2668896, -0.055453625, 0.020696444, -0.5300144, 0.019254193, -11.746746, -0.4373402, 1.8713887, -92.68056, -89.942505, -94.73526, -89.75349],
    [46.399994, 28.674475, -0.0011132268, -2.256013, -0.055393882, 0.011232874, -0.5431991, -0.0004961579, -11.8612385, -0.4120777, 1.8583952, -92.251625, -89.61577, -94.38277, -89.553925],
    [46.440002, 28.544565, -0.00029141427, -2.2342112, -0.054825883, 0.009209487, -0.5456827, -0.015693469, -11.827595, -0.51761615, 1.7998463, -91.84704, -89.325905, -93.98263, -89.58948],
    [46.47998, 28.415684, 0.0002120659, -2.2125888, -0.054407883, 0.01536526, -0.54162604, -0.012250719, -11.715199, -0.67038864, 1.7337576, -91.37481, -89.04486, -93.58956, -89.67638],
    [46.5, 28.35085, 0.00025870878, -2.2019112, -0.054440696, 0.026488645, -0.5335448, 0.0013614821, -11.65359, -0.7762295, 1.7107105, -90.62067, -88.601204, -93.15223, -89.7349],
    [46.54001, 28.167316, -0.000474639, -2.1809192, -0.055100378, 0.04761526, -0.522798, 0.018150534, -11.734102, -0.765546, 2.8093832, -86.30557, -83.33686, -92.29559, -89.26089],
    [46.579987, 27.863855, -0.0031549353, -2.1609035, -0.055820316, 0.08888319, -0.5006357, 0.018996086, -11.445809, -0.5491385, 5.4861526, -79.919304, -70.17628, -90.176155, -85.173065],
    [46.600006, 27.68873, -0.0051070987, -2.1513793, -0.056046676, 0.122898646, -0.47097826, 0.010852282, -11.323768, -0.2789436, 7.087357, -77.151505, -66.2972, -87.2404, -76.52473],
];

/// The packet's fields written where AMS2's `SharedMemory` holds them.
fn page(p: &Packet) -> Vec<u8> {
    let l = shared_memory();
    let v = |i: usize| [p[i], p[i + 1], p[i + 2]].map(f64::from);
    let mut page = Page::zeros(l.size);
    page.u32(l.at("mVersion, mBuildVersionNumber"), 14)
        .f32s(l.at("mOrientation"), &v(2))
        .f32s(l.at("mAngularVelocity"), &v(5))
        .f32s(l.at("mLocalAcceleration"), &v(8))
        .u32(l.at("mSequenceNumber"), 2);
    page.0
}

/// The recording's own physics against what ringpod decodes: in a corner the outer wheels turn faster (the
/// published order FL, FR, RL, RR says which side is which), and the car accelerates towards the inside at about
/// its speed times its yaw rate; the sway cue must point there and the yaw rate turn that way.
#[test]
fn real_corners_sway_and_yaw_towards_them() {
    for (corner, left) in [(&LEFT, true), (&RIGHT, false)] {
        let side = if left { 1.0 } else { -1.0 };
        for p in corner {
            let right_faster = p[12].abs() > p[11].abs() && p[14].abs() > p[13].abs();
            assert_eq!(right_faster, left, "the premise: the outer wheels turn faster ({p:?})");
            let s = decode(&page(p)).unwrap().sample.telemetry;
            let (pitch, roll) = (f64::from(p[2]), f64::from(p[4]));
            let sway = s.force[1] - gravity_from_attitude(pitch, roll)[1];
            let centripetal = f64::from(p[1]) * s.rate[2].abs();
            assert!(
                (0.6 * centripetal..1.1 * centripetal).contains(&(side * sway)) && side * s.rate[2] > 0.2,
                "{} corner: sway {sway:.2} m/s^2, yaw rate {:.2} rad/s, centripetal {centripetal:.2}",
                if left { "left" } else { "right" },
                s.rate[2]
            );
            assert!((s.force[2] - G).abs() < 1.5, "{s:?}");
        }
    }
}

/// Braking at the right-hand corner's end, the nose dips (`sOrientation[0]` falls): the decoded pitch rate
/// (positive nose down), integrated over those packets, must dip it by as much.
#[test]
fn a_real_nose_dip_pitches_down() {
    let dip = &RIGHT[5..];
    let mut integral = 0.0;
    for w in dip.windows(2) {
        let rate = |p: &Packet| decode(&page(p)).unwrap().sample.telemetry.rate[1];
        integral += (rate(&w[0]) + rate(&w[1])) / 2.0 * f64::from(w[1][0] - w[0][0]);
    }
    let down = f64::from(dip[0][2] - dip[dip.len() - 1][2]);
    assert!(down > 0.004, "the premise: the nose dips ({down} rad)");
    assert!(
        integral > 0.5 * down && integral < 2.0 * down,
        "the pitch rate integrates to {integral:.4} rad nose down where the nose dipped {down:.4} rad"
    );
}
