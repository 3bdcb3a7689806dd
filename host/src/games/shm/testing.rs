//! What the shared-memory tests share: C structures laid out from their members as the publishers declare them
//! (so that a test's bytes do not take their offsets from the decoder's constants), pages written at those
//! offsets, memory held in vectors that a test can write into between two reads (the game writing during a copy),
//! and the drive every game's test writes.

use super::{Absent, Memory};

/// A C member's type: its size, which is also its alignment.
#[derive(Debug, Clone, Copy)]
pub enum C {
    I8,
    I16,
    I32,
    F32,
    F64,
}

impl C {
    fn size(self) -> usize {
        match self {
            C::I8 => 1,
            C::I16 => 2,
            C::I32 | C::F32 => 4,
            C::F64 => 8,
        }
    }
}

/// A structure's members' offsets and its size, as a compiler lays them out under `#pragma pack(pack)`.
#[derive(Debug, Clone)]
pub struct Layout {
    members: Vec<(&'static str, usize)>,
    /// `sizeof`.
    pub size: usize,
}

/// Lays out `members` (name, type, array length; a nested structure as an array of bytes of its size with the
/// alignment given by a `C` of that width) packed to `pack` bytes.
pub fn layout(pack: usize, members: &[(&'static str, C, usize)]) -> Layout {
    let (mut at, mut widest, mut out) = (0usize, 1usize, Vec::new());
    for (name, ty, n) in members {
        let align = ty.size().min(pack);
        at = at.next_multiple_of(align);
        widest = widest.max(align);
        out.push((*name, at));
        at += ty.size() * n;
    }
    Layout {
        members: out,
        size: at.next_multiple_of(widest),
    }
}

impl Layout {
    /// A member's offset.
    pub fn at(&self, name: &str) -> usize {
        self.members
            .iter()
            .find(|(n, _)| *n == name)
            .unwrap_or_else(|| panic!("no member {name}"))
            .1
    }
}

/// A page of a mapping, written at byte offsets.
#[derive(Debug, Clone)]
pub struct Page(pub Vec<u8>);

impl Page {
    pub fn zeros(len: usize) -> Self {
        Page(vec![0; len])
    }
    pub fn put(&mut self, at: usize, bytes: &[u8]) -> &mut Self {
        self.0[at..at + bytes.len()].copy_from_slice(bytes);
        self
    }
    pub fn f32s(&mut self, at: usize, v: &[f64]) -> &mut Self {
        for (i, x) in v.iter().enumerate() {
            self.put(at + 4 * i, &(*x as f32).to_le_bytes());
        }
        self
    }
    pub fn f64s(&mut self, at: usize, v: &[f64]) -> &mut Self {
        for (i, x) in v.iter().enumerate() {
            self.put(at + 8 * i, &x.to_le_bytes());
        }
        self
    }
    pub fn i32(&mut self, at: usize, v: i32) -> &mut Self {
        self.put(at, &v.to_le_bytes())
    }
    pub fn u32(&mut self, at: usize, v: u32) -> &mut Self {
        self.put(at, &v.to_le_bytes())
    }
    pub fn u64(&mut self, at: usize, v: u64) -> &mut Self {
        self.put(at, &v.to_le_bytes())
    }
}

/// What a test's game does at a read of its memory: (the read's number from 0, the pages).
pub type Writer = Box<dyn FnMut(usize, &mut [Option<Vec<u8>>]) + Send>;

/// A game's mappings held in vectors (`None`: not there), and what the game writes between reads.
pub struct Fake {
    pub pages: Vec<Option<Vec<u8>>>,
    pub reads: usize,
    pub game: Option<Writer>,
}

impl Fake {
    pub fn new(pages: Vec<Vec<u8>>) -> Self {
        Self {
            pages: pages.into_iter().map(Some).collect(),
            reads: 0,
            game: None,
        }
    }
}

impl Memory for Fake {
    fn read(&mut self, page: usize, at: usize, out: &mut [u8]) -> Result<(), Absent> {
        if let Some(game) = self.game.as_mut() {
            game(self.reads, &mut self.pages);
        }
        self.reads += 1;
        let page = self.pages.get(page).and_then(Option::as_ref).ok_or(Absent)?;
        let bytes = page.get(at..at + out.len()).ok_or(Absent)?;
        out.copy_from_slice(bytes);
        Ok(())
    }
}

/// One moment of the drive every game's test writes: the car's acceleration without gravity (m/s^2, ringpod's
/// axes), its angular rates (rad/s, ringpod's axes), its attitude (rad: nose up, right side down).
#[derive(Debug, Clone, Copy)]
pub struct Moment {
    pub name: &'static str,
    pub accel: [f64; 3],
    pub rate: [f64; 3],
    pub pitch: f64,
    pub roll: f64,
}

/// At rest, accelerating, braking, a left turn, nose up on a slope, rolled right side down while rolling.
pub const DRIVE: [Moment; 6] = [
    Moment {
        name: "at rest",
        accel: [0.0; 3],
        rate: [0.0; 3],
        pitch: 0.0,
        roll: 0.0,
    },
    Moment {
        name: "accelerating",
        accel: [3.0, 0.0, 0.0],
        rate: [0.0; 3],
        pitch: 0.0,
        roll: 0.0,
    },
    Moment {
        name: "braking",
        accel: [-8.0, 0.0, 0.0],
        rate: [0.0, -0.05, 0.0],
        pitch: 0.0,
        roll: 0.0,
    },
    Moment {
        name: "a left turn",
        accel: [0.0, 6.0, 0.0],
        rate: [0.0, 0.0, 0.4],
        pitch: 0.0,
        roll: 0.0,
    },
    Moment {
        name: "nose up",
        accel: [0.0; 3],
        rate: [0.0, -0.2, 0.0],
        pitch: 0.15,
        roll: 0.0,
    },
    Moment {
        name: "rolled right",
        accel: [0.0; 3],
        rate: [0.3, 0.0, 0.0],
        pitch: 0.0,
        roll: 0.12,
    },
];

impl Moment {
    /// The specific force ringpod must decode: the acceleration plus gravity's reaction in the car's axes.
    pub fn force(&self) -> [f64; 3] {
        let g = crate::games::G;
        let (sp, cp) = self.pitch.sin_cos();
        let (sr, cr) = self.roll.sin_cos();
        [
            self.accel[0] + g * sp,
            self.accel[1] + g * cp * sr,
            self.accel[2] + g * cp * cr,
        ]
    }
}

/// Whether two vectors agree to within what `f32` keeps.
pub fn close(a: [f64; 3], b: [f64; 3]) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-4 * (1.0 + y.abs()))
}
