//! Input smoothing against spikes, applied to the telemetry before the washout (off by default).
//!
//! - `median`: the moving median of the last `window` samples (odd, 3 to [`MAX_WINDOW`]), per channel. A spike
//!   shorter than half the window is removed entirely; a step passes whole, `(window - 1) / 2` samples late. It
//!   counts samples, not seconds: its delay is that many sample intervals.
//! - `low_pass`: a low-pass at `corner_hz` (-3 dB there), first order (`1 / (1 + s / w)`) or second order
//!   (Butterworth, damping `1/sqrt 2`, the default), discretised by Tustin at each sample's interval like the
//!   washout's filters. A spike is attenuated, not removed, and its area is kept.
//!
//! Both start at the first sample (the window filled with it, the low-pass settled on it), so that a stream that
//! starts with the vehicle moving does not see a step from zero.

use serde::de::{self, MapAccess, Visitor};
use serde::ser::SerializeStruct;

use super::filter::{Biquad, Section};
use super::Telemetry;
use crate::Real;

/// The largest median window.
pub const MAX_WINDOW: u8 = 15;

/// The input smoothing (TOML table `[smoothing]`, key `kind`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Smoothing {
    /// None (default; `kind = "off"`).
    #[default]
    Off,
    /// Moving median of `window` samples (`kind = "median", window = 5`).
    Median {
        /// Samples, odd, 3 to [`MAX_WINDOW`].
        window: u8,
    },
    /// Low-pass (`kind = "low_pass", corner_hz = 8, order = 2`).
    LowPass {
        /// The corner (Hz), where the gain is -3 dB.
        corner_hz: f64,
        /// 1 or 2 (default 2, Butterworth).
        order: u8,
    },
}

impl Smoothing {
    /// Why it is out of range, if it is: `(key, what it must be)`.
    pub fn check(&self) -> Result<(), (&'static str, &'static str)> {
        match *self {
            Smoothing::Off => Ok(()),
            Smoothing::Median { window } => {
                if (3..=MAX_WINDOW).contains(&window) && window % 2 == 1 {
                    Ok(())
                } else {
                    Err(("smoothing.window", "an odd number of samples from 3 to 15"))
                }
            }
            Smoothing::LowPass { corner_hz, order } => {
                if !(corner_hz.is_finite() && (0.01..=1000.0).contains(&corner_hz)) {
                    Err(("smoothing.corner_hz", "0.01 to 1000 Hz"))
                } else if !(order == 1 || order == 2) {
                    Err(("smoothing.order", "1 or 2"))
                } else {
                    Ok(())
                }
            }
        }
    }
}

const FIELDS: &[&str] = &["kind", "window", "corner_hz", "order"];
const KINDS: &[&str] = &["off", "median", "low_pass"];

impl serde::Serialize for Smoothing {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match *self {
            Smoothing::Off => {
                let mut t = s.serialize_struct("Smoothing", 1)?;
                t.serialize_field("kind", "off")?;
                t.end()
            }
            Smoothing::Median { window } => {
                let mut t = s.serialize_struct("Smoothing", 2)?;
                t.serialize_field("kind", "median")?;
                t.serialize_field("window", &window)?;
                t.end()
            }
            Smoothing::LowPass { corner_hz, order } => {
                let mut t = s.serialize_struct("Smoothing", 3)?;
                t.serialize_field("kind", "low_pass")?;
                t.serialize_field("corner_hz", &corner_hz)?;
                t.serialize_field("order", &order)?;
                t.end()
            }
        }
    }
}

impl<'de> serde::Deserialize<'de> for Smoothing {
    // A table with a `kind` and that kind's keys, read without allocating (the core has no allocator).
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Smoothing;
            fn expecting(&self, f: &mut core::fmt::Formatter) -> core::fmt::Result {
                f.write_str("a table with kind = \"off\", \"median\" (window) or \"low_pass\" (corner_hz, order)")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Smoothing, A::Error> {
                let mut kind: Option<u8> = None;
                let mut window: Option<u8> = None;
                let mut corner: Option<f64> = None;
                let mut order: Option<u8> = None;
                while let Some(key) = map.next_key::<Key>()? {
                    match key {
                        Key::Kind => {
                            let k = map.next_value::<Kind>()?;
                            kind = Some(k.0);
                        }
                        Key::Window => window = Some(map.next_value()?),
                        Key::CornerHz => corner = Some(map.next_value()?),
                        Key::Order => order = Some(map.next_value()?),
                    }
                }
                match kind {
                    None => Err(de::Error::missing_field("kind")),
                    Some(0) if window.is_none() && corner.is_none() && order.is_none() => Ok(Smoothing::Off),
                    Some(0) => Err(de::Error::custom("kind = \"off\" takes no other key")),
                    Some(1) if corner.is_some() || order.is_some() => {
                        Err(de::Error::custom("kind = \"median\" takes `window` only"))
                    }
                    Some(1) => Ok(Smoothing::Median {
                        window: window.ok_or_else(|| de::Error::missing_field("window"))?,
                    }),
                    Some(_) if window.is_some() => Err(de::Error::custom(
                        "kind = \"low_pass\" takes `corner_hz` and `order` only",
                    )),
                    Some(_) => Ok(Smoothing::LowPass {
                        corner_hz: corner.ok_or_else(|| de::Error::missing_field("corner_hz"))?,
                        order: order.unwrap_or(2),
                    }),
                }
            }
        }
        d.deserialize_struct("Smoothing", FIELDS, V)
    }
}

/// A key of the `[smoothing]` table.
enum Key {
    Kind,
    Window,
    CornerHz,
    Order,
}

impl<'de> serde::Deserialize<'de> for Key {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = Key;
            fn expecting(&self, f: &mut core::fmt::Formatter) -> core::fmt::Result {
                f.write_str("kind, window, corner_hz or order")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Key, E> {
                Ok(match v {
                    "kind" => Key::Kind,
                    "window" => Key::Window,
                    "corner_hz" => Key::CornerHz,
                    "order" => Key::Order,
                    other => return Err(de::Error::unknown_field(other, FIELDS)),
                })
            }
        }
        d.deserialize_identifier(V)
    }
}

/// A smoothing kind, by its index in [`KINDS`].
struct Kind(u8);

impl<'de> serde::Deserialize<'de> for Kind {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = Kind;
            fn expecting(&self, f: &mut core::fmt::Formatter) -> core::fmt::Result {
                f.write_str("\"off\", \"median\" or \"low_pass\"")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Kind, E> {
                KINDS
                    .iter()
                    .position(|k| *k == v)
                    .map(|i| Kind(i as u8))
                    .ok_or_else(|| de::Error::unknown_variant(v, KINDS))
            }
        }
        d.deserialize_str(V)
    }
}

/// The six channels of a sample, force then rate.
fn channels<T: Real>(s: &Telemetry<T>) -> [T; 6] {
    [s.force[0], s.force[1], s.force[2], s.rate[0], s.rate[1], s.rate[2]]
}

fn sample<T: Real>(v: [T; 6]) -> Telemetry<T> {
    Telemetry {
        force: [v[0], v[1], v[2]],
        rate: [v[3], v[4], v[5]],
    }
}

/// A running smoother: the state of a [`Smoothing`].
#[derive(Debug, Clone)]
pub enum Smoother<T: Real> {
    /// Passes samples through.
    Off,
    /// The last `window` samples, a ring; `next` is where the next one goes.
    Median {
        /// Samples in the window.
        window: usize,
        /// The samples, channel by channel (force then rate).
        ring: [[T; 6]; MAX_WINDOW as usize],
        /// Where the next sample goes.
        next: usize,
    },
    /// One low-pass per channel.
    LowPass([Biquad<T>; 6]),
}

impl<T: Real> Smoother<T> {
    /// The smoother of a (valid) smoothing, empty.
    pub fn new(smoothing: &Smoothing) -> Self {
        match *smoothing {
            Smoothing::Off => Smoother::Off,
            Smoothing::Median { window } => Smoother::Median {
                window: usize::from(window.clamp(1, MAX_WINDOW)),
                ring: [[T::zero(); 6]; MAX_WINDOW as usize],
                next: 0,
            },
            Smoothing::LowPass { corner_hz, order } => {
                let w = T::of(2.0 * core::f64::consts::PI * corner_hz);
                let f = if order == 1 {
                    Biquad::first_order(Section::first_order_low_pass(w))
                } else {
                    Biquad::new(Section::low_pass(w, T::of(core::f64::consts::FRAC_1_SQRT_2)))
                };
                Smoother::LowPass([f; 6])
            }
        }
    }

    /// Starts at `s`, as if it had been steady: returns it.
    pub fn begin(&mut self, s: &Telemetry<T>) -> Telemetry<T> {
        let v = channels(s);
        match self {
            Smoother::Off => {}
            Smoother::Median { ring, next, .. } => {
                *ring = [v; MAX_WINDOW as usize];
                *next = 0;
            }
            Smoother::LowPass(f) => {
                for (f, v) in f.iter_mut().zip(v) {
                    f.settle(v);
                }
            }
        }
        *s
    }

    /// Takes a sample `dt` seconds after the last one; returns the smoothed sample.
    pub fn step(&mut self, s: &Telemetry<T>, dt: T) -> Telemetry<T> {
        let v = channels(s);
        match self {
            Smoother::Off => *s,
            Smoother::Median { window, ring, next } => {
                let n = *window;
                ring[*next] = v;
                *next = (*next + 1) % n;
                sample(core::array::from_fn(|c| {
                    let mut w = [T::zero(); MAX_WINDOW as usize];
                    for (k, slot) in w.iter_mut().take(n).enumerate() {
                        *slot = ring[k][c];
                    }
                    // Insertion sort of at most 15 finite numbers.
                    for i in 1..n {
                        let mut j = i;
                        while j > 0 && w[j - 1] > w[j] {
                            w.swap(j - 1, j);
                            j -= 1;
                        }
                    }
                    w[n / 2]
                }))
            }
            Smoother::LowPass(f) => sample(core::array::from_fn(|c| f[c].step(v[c], dt))),
        }
    }
}
