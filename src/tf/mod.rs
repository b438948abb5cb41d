//! Piecewise-linear transfer functions: breakpoints, extinction and
//! colour, emission models, presets, JSON and ParaView import.
//!
//! # Model
//! A [`TransferFunction`] is a sorted list of [`Node`]s. Between two nodes
//! every channel is linear in the scalar `s`; two nodes at the same scalar are
//! a jump (the first holds the left limit, the second the right limit); outside
//! the node range every channel is constant. Channels:
//! * extinction `tau >= 0` per unit length;
//! * RGB colour `c`: the glow colour (what an opaque slab of the material looks
//!   like);
//! * for [`EmissionModel::Independent`], an RGB emission `E` per unit length.
//!
//! The source term along a ray is `tau * c` for [`EmissionModel::Glow`] (the
//! Williams-Max volume density model, the default) and `E` for independent
//! emission. Point evaluation is right-continuous at jumps. This module
//! holds the data only: the exact integrals live in [`crate::integrate`],
//! which also implements its `RayMaterial` (what the renderers need of a
//! material) for `TransferFunction`.
//!
//! Channels given as separate point lists (VTK style: opacity points and
//! colour points) are merged onto the union of their scalars by
//! [`TransferFunction::from_channels`]; a jump in any channel becomes a jump
//! node pair for all channels.
//!
//! Files: see [`json`] for the project format, VTK-style files such as
//! `bench_tf.json`, and ParaView colour maps; [`presets`] for the named
//! colour maps and the default transfer function.

mod error;
pub mod json;
mod paraview;
pub mod presets;

pub use error::TfError;
pub use presets::{preset, preset_names, Opacity};

/// How a material emits light.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum EmissionModel {
    /// Glowing particles: source = extinction x colour (CLI default).
    #[default]
    Glow,
    /// Independent emission: source = E(s), its own piecewise-linear RGB.
    Independent,
}

/// One node of a transfer function.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Node {
    pub s: f64,
    /// Extinction per unit length.
    pub tau: f64,
    /// Glow colour.
    pub color: [f64; 3],
    /// Emission per unit length (used by [`EmissionModel::Independent`]).
    pub emission: [f64; 3],
}

/// A piecewise-linear transfer function (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct TransferFunction {
    pub(crate) s: Vec<f64>,
    pub(crate) tau: Vec<f64>,
    /// Colour used by the integral: glow colour or emission.
    pub(crate) col: Vec<[f64; 3]>,
    /// Glow colour (kept for both models: display, glow limits).
    pub(crate) color: Vec<[f64; 3]>,
    pub(crate) model: EmissionModel,
    pub(crate) breaks: Vec<f64>,
    /// The field the file names (`scalar` key), if any.
    pub scalar: Option<String>,
    /// Opacity unit distance the file used, if any (informational).
    pub unit_distance: Option<f64>,
}

/// A channel given as its own sorted point list: `(s, value)`.
pub type Channel<'a, const N: usize> = &'a [(f64, [f64; N])];

impl TransferFunction {
    /// Builds a transfer function from nodes (sorted by `s`; a jump is two
    /// nodes at one scalar). Validates: non-empty, finite, sorted, at most two
    /// nodes per scalar, non-negative extinction, colour and emission.
    pub fn from_nodes(nodes: &[Node], model: EmissionModel) -> Result<Self, TfError> {
        const WHAT: &str = "transfer function";
        if nodes.is_empty() {
            return Err(TfError::Empty);
        }
        check_sorted(WHAT, nodes.iter().map(|n| n.s))?;
        for (i, n) in nodes.iter().enumerate() {
            check_value(WHAT, i, "extinction", n.tau)?;
            for c in n.color {
                check_value(WHAT, i, "colour", c)?;
            }
            if model == EmissionModel::Independent {
                for c in n.emission {
                    check_value(WHAT, i, "emission", c)?;
                }
            }
        }
        let s: Vec<f64> = nodes.iter().map(|n| n.s).collect();
        let mut breaks = s.clone();
        breaks.dedup();
        let color: Vec<[f64; 3]> = nodes.iter().map(|n| n.color).collect();
        let col = match model {
            EmissionModel::Glow => color.clone(),
            EmissionModel::Independent => nodes.iter().map(|n| n.emission).collect(),
        };
        Ok(Self {
            s,
            tau: nodes.iter().map(|n| n.tau).collect(),
            col,
            color,
            model,
            breaks,
            scalar: None,
            unit_distance: None,
        })
    }

    /// Merges separately sampled channels (each sorted by scalar, jumps as two
    /// points at one scalar) onto the union of their scalars. `emission` is
    /// required for (and only used by) [`EmissionModel::Independent`].
    pub fn from_channels(
        tau: Channel<1>,
        color: Channel<3>,
        emission: Option<Channel<3>>,
        model: EmissionModel,
    ) -> Result<Self, TfError> {
        if tau.is_empty() || color.is_empty() {
            return Err(TfError::Empty);
        }
        check_channel("extinction points", tau)?;
        check_channel("colour points", color)?;
        let emission = match (model, emission) {
            (EmissionModel::Independent, Some(e)) if !e.is_empty() => {
                check_channel("emission points", e)?;
                Some(e)
            }
            (EmissionModel::Independent, _) => {
                return Err(TfError::Format(
                    "independent emission needs emission points".into(),
                ))
            }
            (EmissionModel::Glow, _) => None,
        };
        let mut all: Vec<f64> = tau.iter().map(|p| p.0).collect();
        all.extend(color.iter().map(|p| p.0));
        if let Some(e) = emission {
            all.extend(e.iter().map(|p| p.0));
        }
        all.sort_by(f64::total_cmp);
        all.dedup();
        let mut nodes = Vec::with_capacity(all.len() + 4);
        for &s in &all {
            let left = Node {
                s,
                tau: eval_channel(tau, s, Side::Left)[0],
                color: eval_channel(color, s, Side::Left),
                emission: emission.map_or([0.0; 3], |e| eval_channel(e, s, Side::Left)),
            };
            let right = Node {
                s,
                tau: eval_channel(tau, s, Side::Right)[0],
                color: eval_channel(color, s, Side::Right),
                emission: emission.map_or([0.0; 3], |e| eval_channel(e, s, Side::Right)),
            };
            nodes.push(left);
            if right != left {
                nodes.push(right);
            }
        }
        Self::from_nodes(&nodes, model)
    }

    /// Deduplicated breakpoints (same as `RayMaterial::breakpoints`).
    #[inline]
    pub(crate) fn breakpoints_slice(&self) -> &[f64] {
        &self.breaks
    }

    /// The emission model.
    pub fn model(&self) -> EmissionModel {
        self.model
    }

    /// The nodes, in order.
    pub fn nodes(&self) -> Vec<Node> {
        (0..self.s.len())
            .map(|i| Node {
                s: self.s[i],
                tau: self.tau[i],
                color: self.color[i],
                emission: match self.model {
                    EmissionModel::Glow => [0.0; 3],
                    EmissionModel::Independent => self.col[i],
                },
            })
            .collect()
    }

    /// Scalar range covered by the nodes.
    pub fn scalar_range(&self) -> (f64, f64) {
        (self.s[0], self.s[self.s.len() - 1])
    }

    /// The same function of `s - origin`: every node moved by `-origin`
    /// (for a field shifted by the same origin). `None` where the rounding
    /// of the moved nodes would merge two of them (nodes far from the
    /// origin, closer together than its ulps), so that the shifted function
    /// is the same one.
    pub fn shifted(&self, origin: f64) -> Option<TransferFunction> {
        let mov = |v: &[f64]| v.iter().map(|&x| x - origin).collect::<Vec<f64>>();
        let (s, breaks) = (mov(&self.s), mov(&self.breaks));
        let same_order = |a: &[f64], b: &[f64]| {
            a.windows(2)
                .zip(b.windows(2))
                .all(|(a, b)| (a[0] < a[1]) == (b[0] < b[1]))
        };
        if !s.iter().all(|x| x.is_finite()) || !same_order(&self.s, &s) {
            return None;
        }
        Some(TransferFunction {
            s,
            breaks,
            ..self.clone()
        })
    }

    /// Largest extinction of any node (the maximum of the function).
    pub fn max_tau(&self) -> f64 {
        self.tau.iter().copied().fold(0.0, f64::max)
    }

    /// Largest source term per channel (`tau * c` or `E`) over all nodes; for
    /// glow this bounds the product of the two linear channels only up to the
    /// product of their maxima, which is what is returned.
    pub fn max_source(&self) -> [f64; 3] {
        let mut m = [0.0f64; 3];
        for c in &self.col {
            m = std::array::from_fn(|k| m[k].max(c[k]));
        }
        if self.model == EmissionModel::Glow {
            let t = self.max_tau();
            m.iter_mut().for_each(|v| *v *= t);
        }
        m
    }

    /// Index `idx` = number of nodes with `s_i <= s` (the piece to the right
    /// of node `idx - 1`).
    #[inline]
    pub(crate) fn piece_index(&self, s: f64) -> usize {
        self.s.partition_point(|&x| x <= s)
    }

    /// Extinction and integral colour of piece `idx` evaluated at `s`, using
    /// the exact node values when `s` is a node of that piece.
    #[inline]
    pub(crate) fn eval_piece(&self, idx: usize, s: f64) -> (f64, [f64; 3]) {
        let n = self.s.len();
        if idx == 0 {
            return (self.tau[0], self.col[0]);
        }
        if idx >= n {
            return (self.tau[n - 1], self.col[n - 1]);
        }
        let j = idx - 1;
        let (s0, s1) = (self.s[j], self.s[j + 1]);
        if s == s0 {
            return (self.tau[j], self.col[j]);
        }
        if s == s1 {
            return (self.tau[j + 1], self.col[j + 1]);
        }
        let u = (s - s0) / (s1 - s0);
        let (c0, c1) = (self.col[j], self.col[j + 1]);
        (
            self.tau[j] + (self.tau[j + 1] - self.tau[j]) * u,
            [
                c0[0] + (c1[0] - c0[0]) * u,
                c0[1] + (c1[1] - c0[1]) * u,
                c0[2] + (c1[2] - c0[2]) * u,
            ],
        )
    }

    /// Glow colour at `s` (right-continuous), for both models.
    pub fn color_at(&self, s: f64) -> [f64; 3] {
        let idx = self.piece_index(s);
        let n = self.s.len();
        if idx == 0 || idx >= n || s == self.s[idx - 1] {
            return self.color[idx.clamp(1, n) - 1];
        }
        let j = idx - 1;
        let u = (s - self.s[j]) / (self.s[j + 1] - self.s[j]);
        let (c0, c1) = (self.color[j], self.color[j + 1]);
        std::array::from_fn(|k| c0[k] + (c1[k] - c0[k]) * u)
    }

    /// Extinction at `s` (right-continuous).
    pub fn tau_at(&self, s: f64) -> f64 {
        self.eval_piece(self.piece_index(s), s).0
    }
}

/// Largest magnitude accepted for any scalar, extinction, colour or
/// emission value: keeps every product and integral-function sum finite.
pub const VALUE_LIMIT: f64 = 1e100;

#[derive(Clone, Copy, PartialEq, Eq)]
enum Side {
    Left,
    Right,
}

/// Left or right limit of a sorted channel at `s` (constant outside).
fn eval_channel<const N: usize>(p: Channel<N>, s: f64, side: Side) -> [f64; N] {
    let n = p.len();
    match side {
        Side::Right => {
            let i = p.partition_point(|q| q.0 <= s); // nodes <= s
            if i == 0 {
                return p[0].1;
            }
            if i >= n || p[i - 1].0 == s {
                return p[i - 1].1;
            }
            lerp_points(p[i - 1], p[i], s)
        }
        Side::Left => {
            let i = p.partition_point(|q| q.0 < s); // first node >= s
            if i >= n {
                return p[n - 1].1;
            }
            if i == 0 || p[i].0 == s {
                return p[i].1;
            }
            lerp_points(p[i - 1], p[i], s)
        }
    }
}

fn lerp_points<const N: usize>(a: (f64, [f64; N]), b: (f64, [f64; N]), s: f64) -> [f64; N] {
    let u = (s - a.0) / (b.0 - a.0);
    std::array::from_fn(|k| a.1[k] + (b.1[k] - a.1[k]) * u)
}

fn check_sorted(what: &'static str, s: impl Iterator<Item = f64>) -> Result<(), TfError> {
    let mut prev = f64::NEG_INFINITY;
    let mut run = 0;
    for (index, value) in s.enumerate() {
        if !value.is_finite() {
            return Err(TfError::NonFiniteScalar { what, index });
        }
        if value.abs() > VALUE_LIMIT {
            return Err(TfError::OutOfRange {
                what,
                index,
                field: "scalar",
                value,
            });
        }
        if value < prev {
            return Err(TfError::Unsorted {
                what,
                index,
                value,
                previous: prev,
            });
        }
        run = if value == prev { run + 1 } else { 1 };
        if run > 2 {
            return Err(TfError::TooManyAtOneScalar { what, value });
        }
        prev = value;
    }
    Ok(())
}

fn check_value(
    what: &'static str,
    index: usize,
    field: &'static str,
    v: f64,
) -> Result<(), TfError> {
    if !v.is_finite() {
        return Err(TfError::NonFinite { what, index, field });
    }
    if v > VALUE_LIMIT {
        return Err(TfError::OutOfRange {
            what,
            index,
            field,
            value: v,
        });
    }
    if v < 0.0 {
        return Err(TfError::Negative {
            what,
            index,
            field,
            value: v,
        });
    }
    Ok(())
}

fn check_channel<const N: usize>(what: &'static str, p: Channel<N>) -> Result<(), TfError> {
    check_sorted(what, p.iter().map(|q| q.0))?;
    for (i, q) in p.iter().enumerate() {
        for v in q.1 {
            check_value(what, i, "value", v)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::RayMaterial;

    fn n(s: f64, tau: f64, c: f64) -> Node {
        Node {
            s,
            tau,
            color: [c, c, c],
            emission: [0.0; 3],
        }
    }

    #[test]
    fn a_shifted_function_is_the_same_function_of_the_moved_scalar() {
        let o = 1.0;
        let tf = TransferFunction::from_nodes(
            &[
                n(o, 1.0, 0.0),
                n(o + 0.5e-12, 3.0, 1.0),
                n(o + 0.5e-12, 10.0, 0.5),
                n(o + 1e-12, 0.0, 0.5),
            ],
            EmissionModel::Glow,
        )
        .unwrap();
        let moved = tf.shifted(o).unwrap();
        assert_eq!(moved.breakpoints_slice().len(), 3);
        for k in 0..=8 {
            let s = o + 0.125e-12 * k as f64;
            assert_eq!(moved.tau_at(s - o), tf.tau_at(s), "{k}");
            assert_eq!(moved.color_at(s - o), tf.color_at(s), "{k}");
        }
        // Two nodes 1e-3 apart, 1e12 from zero: moved by 1e16 (ulp 2) they
        // round together; moved by 1 they stay apart.
        let far = TransferFunction::from_nodes(
            &[
                n(-1e12, 1.0, 0.0),
                n(-1e12 + 1e-3, 1.0, 0.0),
                n(0.0, 1.0, 1.0),
            ],
            EmissionModel::Glow,
        )
        .unwrap();
        assert!(far.shifted(1e16).is_none());
        assert!(far.shifted(1.0).is_some());
    }

    #[test]
    fn evaluation_is_right_continuous_and_clamped() {
        let tf = TransferFunction::from_nodes(
            &[
                n(0.0, 1.0, 0.0),
                n(1.0, 3.0, 1.0),
                n(1.0, 10.0, 0.5),
                n(2.0, 0.0, 0.5),
            ],
            EmissionModel::Glow,
        )
        .unwrap();
        assert_eq!(tf.tau_at(-5.0), 1.0);
        assert_eq!(tf.tau_at(0.5), 2.0);
        assert_eq!(tf.tau_at(1.0), 10.0);
        assert_eq!(tf.tau_at(1.5), 5.0);
        assert_eq!(tf.tau_at(9.0), 0.0);
        assert_eq!(tf.breakpoints(), &[0.0, 1.0, 2.0]);
        let m = tf.material(0.5);
        assert_eq!(m.source, [1.0, 1.0, 1.0]);
        assert_eq!(tf.color_at(1.0), [0.5; 3]);
        assert_eq!(tf.color_at(0.25), [0.25; 3]);
    }

    #[test]
    fn channels_merge_with_jumps() {
        let tau = [(0.0, [0.0]), (1.0, [2.0]), (1.0, [4.0]), (3.0, [4.0])];
        let col = [(0.0, [0.0, 0.0, 0.0]), (2.0, [1.0, 1.0, 1.0])];
        let tf = TransferFunction::from_channels(&tau, &col, None, EmissionModel::Glow).unwrap();
        assert_eq!(tf.s, vec![0.0, 1.0, 1.0, 2.0, 3.0]);
        assert_eq!(tf.tau, vec![0.0, 2.0, 4.0, 4.0, 4.0]);
        assert_eq!(tf.color[1], [0.5; 3]);
        assert_eq!(tf.color[4], [1.0; 3]);
    }

    #[test]
    fn bad_nodes_are_rejected() {
        let e = TransferFunction::from_nodes(&[], EmissionModel::Glow).unwrap_err();
        assert!(matches!(e, TfError::Empty));
        let e = TransferFunction::from_nodes(
            &[n(1.0, 1.0, 0.0), n(0.0, 1.0, 0.0)],
            EmissionModel::Glow,
        )
        .unwrap_err();
        assert!(matches!(e, TfError::Unsorted { index: 1, .. }), "{e}");
        let e =
            TransferFunction::from_nodes(&[n(0.0, -1.0, 0.0)], EmissionModel::Glow).unwrap_err();
        assert!(matches!(e, TfError::Negative { .. }), "{e}");
        let e = TransferFunction::from_nodes(&[n(0.0, f64::NAN, 0.0)], EmissionModel::Glow)
            .unwrap_err();
        assert!(matches!(e, TfError::NonFinite { .. }), "{e}");
        let e = TransferFunction::from_nodes(
            &[n(0.0, 1.0, 0.0), n(0.0, 1.0, 0.0), n(0.0, 1.0, 0.0)],
            EmissionModel::Glow,
        )
        .unwrap_err();
        assert!(matches!(e, TfError::TooManyAtOneScalar { .. }), "{e}");
    }
}
