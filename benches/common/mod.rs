//! What the benchmarks of the integrals and the tables share: their seeded
//! generator and their transfer function with a jump.

use zoovr::tf::{EmissionModel, Node, TransferFunction};

/// Xorshift64 (Marsaglia 13/7/17), the benchmarks' fixed-seed generator.
pub struct Rng(pub u64);

impl Rng {
    /// Uniform in `[0, 1)`.
    pub fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A 7-node transfer function over [0, 1] with a jump at 0.35, extinction
/// up to 8 per unit length.
pub fn jump_tf() -> TransferFunction {
    let n = |s, tau, c: [f64; 3]| Node {
        s,
        tau,
        color: c,
        emission: [0.0; 3],
    };
    TransferFunction::from_nodes(
        &[
            n(0.0, 0.0, [1.0, 0.0, 0.0]),
            n(0.2, 2.0, [1.0, 0.5, 0.0]),
            n(0.35, 5.0, [1.0, 1.0, 0.0]),
            n(0.35, 0.5, [0.0, 1.0, 0.0]),
            n(0.6, 8.0, [0.0, 1.0, 1.0]),
            n(0.8, 1.0, [0.0, 0.0, 1.0]),
            n(1.0, 0.0, [1.0, 0.0, 1.0]),
        ],
        EmissionModel::Glow,
    )
    .expect("valid")
}
