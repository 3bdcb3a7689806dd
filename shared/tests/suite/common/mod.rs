//! Helpers shared by the test modules.

pub mod device;

/// A 64-bit linear congruential generator (Knuth's MMIX constants): the same numbers on every run and machine,
/// without a dependency.
pub struct Lcg(pub u64);

impl Lcg {
    /// Uniform in `[-1, 1)`.
    pub fn uniform(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}
