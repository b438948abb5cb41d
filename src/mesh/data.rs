//! Data arrays as a mesh carries them: named arrays of point or cell data,
//! with their values as the file stored them (`f32` and `f64` without loss,
//! integers widened to `i64`) and their VTK type name for writing back.
//!
//! These types belong to the mesh (readers fill them, subsets and ghost
//! filtering carry them along); [`crate::field`] re-exports them and turns
//! one array into the scalar field a render integrates.

/// The values of a data array.
#[derive(Clone, Debug, PartialEq)]
pub enum ArrayData {
    F32(Vec<f32>),
    F64(Vec<f64>),
    /// Any integer type, widened.
    Int(Vec<i64>),
}

impl ArrayData {
    /// Number of scalar values (tuples x components).
    pub fn len(&self) -> usize {
        match self {
            ArrayData::F32(v) => v.len(),
            ArrayData::F64(v) => v.len(),
            ArrayData::Int(v) => v.len(),
        }
    }

    /// Whether there are no values.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Value `i` as `f64`.
    #[inline]
    pub fn get(&self, i: usize) -> f64 {
        match self {
            ArrayData::F32(v) => v[i] as f64,
            ArrayData::F64(v) => v[i],
            ArrayData::Int(v) => v[i] as f64,
        }
    }

    /// Whether the values are floating point.
    pub fn is_float(&self) -> bool {
        !matches!(self, ArrayData::Int(_))
    }
}

/// Where an array lives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Association {
    Point,
    Cell,
}

impl Association {
    /// `"point"` or `"cell"`.
    pub fn as_str(self) -> &'static str {
        match self {
            Association::Point => "point",
            Association::Cell => "cell",
        }
    }
}

/// A named array with `components` values per tuple.
#[derive(Clone, Debug, PartialEq)]
pub struct DataArray {
    /// Name, percent-decoded.
    pub name: String,
    /// Values per tuple (1 for scalars, 3 for vectors, 6 or 9 for tensors).
    pub components: usize,
    /// The values, tuple-major.
    pub data: ArrayData,
    /// The VTK type name of the stored values (`Float32`, `Int64`, ...).
    pub vtk_type: String,
}

impl DataArray {
    /// Number of tuples.
    pub fn tuples(&self) -> usize {
        self.data.len() / self.components.max(1)
    }

    /// Component `k` of tuple `i`.
    #[inline]
    pub fn component(&self, i: usize, k: usize) -> f64 {
        self.data.get(i * self.components + k)
    }

    /// Euclidean norm of tuple `i`.
    pub fn magnitude(&self, i: usize) -> f64 {
        let mut s = 0.0;
        for k in 0..self.components {
            let v = self.component(i, k);
            s += v * v;
        }
        s.sqrt()
    }

    /// Min and max over finite values of the component (or magnitude when
    /// `component` is `None`); `None` when no value is finite.
    pub fn range(&self, component: Option<usize>) -> Option<(f64, f64)> {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for i in 0..self.tuples() {
            let v = match component {
                Some(k) => self.component(i, k),
                None => self.magnitude(i),
            };
            if v.is_finite() {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        (lo <= hi).then_some((lo, hi))
    }
}
