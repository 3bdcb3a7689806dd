//! Switch inputs: electrical levels to debounced logical levels, and the bit layout the boards read them in.
//!
//! A board reads its input pins into one `u16` of electrical levels (1 = high) in the order of [`InputBit`];
//! [`InputConfig::active_low`] says which inputs are active when low (a normally-closed e-stop chain to ground
//! reads high when open, a switch with a pull-up reads low when pressed). The [`Debouncer`] then accepts a new
//! level of an input only after it has been read the same `samples` times in a row, so a bouncing contact
//! changes nothing until it settles, and a single spike never latches a fault.

use super::Inputs;

/// Position of each input in the raw and logical words.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InputBit {
    /// E-stop chain open (bit 0).
    EStop,
    /// Home switch of an axis (bits 1-6).
    Home(u8),
    /// Far end-of-travel switch of an axis (bits 7-12).
    Limit(u8),
    /// LOGIC_OK supply sense (bit 13).
    LogicOk,
    /// POWER_OK supply sense (bit 14).
    PowerOk,
}

impl InputBit {
    /// The bit's mask (zero for an axis index above 5).
    pub const fn mask(self) -> u16 {
        match self {
            InputBit::EStop => 1,
            InputBit::Home(a) if a < 6 => 1 << (1 + a),
            InputBit::Limit(a) if a < 6 => 1 << (7 + a),
            InputBit::Home(_) | InputBit::Limit(_) => 0,
            InputBit::LogicOk => 1 << 13,
            InputBit::PowerOk => 1 << 14,
        }
    }
}

/// How the inputs are wired and filtered.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct InputConfig {
    /// Bit per input ([`InputBit`] layout): active when the pin is low.
    pub active_low: u16,
    /// Consecutive equal samples (one per millisecond) before a level is accepted.
    pub debounce_samples: u8,
}

impl Default for InputConfig {
    /// Switches with pull-ups that close to ground (active low); an NC e-stop chain to ground (open = high); supply
    /// sense high when up; 3 ms of debouncing.
    fn default() -> Self {
        let mut switches = 0;
        let mut a = 0;
        while a < 6 {
            switches |= InputBit::Home(a).mask() | InputBit::Limit(a).mask();
            a += 1;
        }
        Self {
            active_low: switches,
            debounce_samples: 3,
        }
    }
}

impl Inputs {
    /// The inputs of a logical input word (bits in [`InputBit`]'s layout, polarity already applied by the
    /// [`Debouncer`]: a set bit is an active input). Inputs of axes beyond six are not the controller's.
    pub fn from_word(logical: u16) -> Self {
        let mut home = 0;
        let mut limits = 0;
        for a in 0..6u8 {
            if logical & InputBit::Home(a).mask() != 0 {
                home |= 1 << a;
            }
            if logical & InputBit::Limit(a).mask() != 0 {
                limits |= 1 << a;
            }
        }
        Inputs {
            estop_open: logical & InputBit::EStop.mask() != 0,
            home,
            limits,
            logic_ok: logical & InputBit::LogicOk.mask() != 0,
            power_ok: logical & InputBit::PowerOk.mask() != 0,
        }
    }

    /// The logical input word (the inverse of [`Inputs::from_word`] for axes 0-5).
    pub fn word(&self) -> u16 {
        let mut w = 0;
        for a in 0..6u8 {
            if self.home & (1 << a) != 0 {
                w |= InputBit::Home(a).mask();
            }
            if self.limits & (1 << a) != 0 {
                w |= InputBit::Limit(a).mask();
            }
        }
        if self.estop_open {
            w |= InputBit::EStop.mask();
        }
        if self.logic_ok {
            w |= InputBit::LogicOk.mask();
        }
        if self.power_ok {
            w |= InputBit::PowerOk.mask();
        }
        w
    }
}

/// Per-input debouncing of sampled levels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Debouncer {
    config: InputConfig,
    stable: u16,
    count: [u8; 16],
}

impl Debouncer {
    /// A debouncer whose accepted levels start at `initial_raw` (the pins as read at reset: the machine is taken
    /// as it is found, so an e-stop already open at power-up is open, not a change).
    pub fn new(config: InputConfig, initial_raw: u16) -> Self {
        Self {
            config,
            stable: initial_raw ^ config.active_low,
            count: [0; 16],
        }
    }

    /// Feeds one sample of the electrical levels; returns the accepted logical levels.
    pub fn sample(&mut self, raw: u16) -> u16 {
        let logical = raw ^ self.config.active_low;
        let need = self.config.debounce_samples.max(1);
        for (bit, count) in self.count.iter_mut().enumerate() {
            let mask = 1u16 << bit;
            if (logical ^ self.stable) & mask == 0 {
                *count = 0;
                continue;
            }
            *count = count.saturating_add(1);
            if *count >= need {
                self.stable ^= mask;
                *count = 0;
            }
        }
        self.stable
    }

    /// The accepted logical levels.
    pub fn stable(&self) -> u16 {
        self.stable
    }

    /// Whether some input is between levels (read differently from its accepted level, not yet accepted): the
    /// board keeps sampling until this is false, then waits for the next edge.
    pub fn settling(&self) -> bool {
        self.count.iter().any(|c| *c > 0)
    }

    /// The configuration.
    pub fn config(&self) -> &InputConfig {
        &self.config
    }
}
