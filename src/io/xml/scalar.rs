//! VTK XML scalar types and the conversion of their bytes into typed values.
//!
//! [`Scalar`] names a `type=` attribute; [`Target`] is the value type an array
//! is decoded into (`f64` points, `f32` data kept bit-exact, `i64` integers,
//! `u32` ids, `u8` cell types). Integers that do not fit the target map to a
//! sentinel (`u32::MAX`, `u8::MAX`) that the readers reject, never wrap.
//! [`convert_par`] converts a byte slice in either byte order in parallel
//! chunks.

use rayon::prelude::*;

/// Values converted per parallel task.
const CONVERT_CHUNK: usize = 1 << 16;

/// A VTK XML scalar type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F32,
    F64,
}

impl Scalar {
    /// Parses a `type=` attribute (`Float32`, `Int64`, ...).
    pub fn parse(s: &str) -> Option<Scalar> {
        Some(match s {
            "Int8" | "Char" => Scalar::I8,
            "UInt8" | "UnsignedChar" => Scalar::U8,
            "Int16" => Scalar::I16,
            "UInt16" => Scalar::U16,
            "Int32" => Scalar::I32,
            "UInt32" => Scalar::U32,
            "Int64" | "IdType" => Scalar::I64,
            "UInt64" => Scalar::U64,
            "Float32" => Scalar::F32,
            "Float64" => Scalar::F64,
            _ => return None,
        })
    }

    /// Bytes per value.
    pub fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::I64 | Scalar::U64 | Scalar::F64 => 8,
        }
    }

    /// The VTK name (as [`crate::field::DataArray::vtk_type`] stores it).
    pub fn name(self) -> &'static str {
        match self {
            Scalar::I8 => "Int8",
            Scalar::U8 => "UInt8",
            Scalar::I16 => "Int16",
            Scalar::U16 => "UInt16",
            Scalar::I32 => "Int32",
            Scalar::U32 => "UInt32",
            Scalar::I64 => "Int64",
            Scalar::U64 => "UInt64",
            Scalar::F32 => "Float32",
            Scalar::F64 => "Float64",
        }
    }
}

/// A value type arrays are decoded into. Out-of-range integers map to a
/// sentinel the caller rejects (`u32::MAX`, `u8::MAX`) rather than wrapping.
pub trait Target: Copy + Default + Send + Sync {
    fn from_i64(v: i64) -> Self;
    fn from_u64(v: u64) -> Self;
    fn from_f64(v: f64) -> Self;
    fn from_f32(v: f32) -> Self {
        Self::from_f64(v as f64)
    }
}

impl Target for f64 {
    fn from_i64(v: i64) -> Self {
        v as f64
    }
    fn from_u64(v: u64) -> Self {
        v as f64
    }
    fn from_f64(v: f64) -> Self {
        v
    }
}

impl Target for f32 {
    fn from_i64(v: i64) -> Self {
        v as f32
    }
    fn from_u64(v: u64) -> Self {
        v as f32
    }
    fn from_f64(v: f64) -> Self {
        v as f32
    }
    fn from_f32(v: f32) -> Self {
        v
    }
}

impl Target for i64 {
    fn from_i64(v: i64) -> Self {
        v
    }
    fn from_u64(v: u64) -> Self {
        i64::try_from(v).unwrap_or(i64::MAX)
    }
    fn from_f64(v: f64) -> Self {
        v as i64
    }
}

impl Target for u32 {
    fn from_i64(v: i64) -> Self {
        u32::try_from(v).unwrap_or(u32::MAX)
    }
    fn from_u64(v: u64) -> Self {
        u32::try_from(v).unwrap_or(u32::MAX)
    }
    fn from_f64(v: f64) -> Self {
        if v.fract() == 0.0 && (0.0..u32::MAX as f64).contains(&v) {
            v as u32
        } else {
            u32::MAX
        }
    }
}

impl Target for u8 {
    fn from_i64(v: i64) -> Self {
        u8::try_from(v).unwrap_or(u8::MAX)
    }
    fn from_u64(v: u64) -> Self {
        u8::try_from(v).unwrap_or(u8::MAX)
    }
    fn from_f64(v: f64) -> Self {
        if v.fract() == 0.0 && (0.0..255.0).contains(&v) {
            v as u8
        } else {
            u8::MAX
        }
    }
}

macro_rules! convert_as {
    ($src:expr, $out:expr, $be:expr, $t:ty, $f:ident) => {{
        const S: usize = std::mem::size_of::<$t>();
        for (o, c) in $out.iter_mut().zip($src.chunks_exact(S)) {
            let mut a = [0u8; S];
            a.copy_from_slice(c);
            let v = if $be {
                <$t>::from_be_bytes(a)
            } else {
                <$t>::from_le_bytes(a)
            };
            *o = T::$f(v.into());
        }
    }};
}

/// Converts `src` (values of `ty`, `src.len() == out.len() * ty.size()`).
pub fn convert_bytes<T: Target>(src: &[u8], ty: Scalar, be: bool, out: &mut [T]) {
    match ty {
        Scalar::I8 => convert_as!(src, out, be, i8, from_i64),
        Scalar::U8 => convert_as!(src, out, be, u8, from_u64),
        Scalar::I16 => convert_as!(src, out, be, i16, from_i64),
        Scalar::U16 => convert_as!(src, out, be, u16, from_u64),
        Scalar::I32 => convert_as!(src, out, be, i32, from_i64),
        Scalar::U32 => convert_as!(src, out, be, u32, from_u64),
        Scalar::I64 => convert_as!(src, out, be, i64, from_i64),
        Scalar::U64 => convert_as!(src, out, be, u64, from_u64),
        Scalar::F32 => convert_as!(src, out, be, f32, from_f32),
        Scalar::F64 => convert_as!(src, out, be, f64, from_f64),
    }
}

/// [`convert_bytes`] in parallel chunks, into a new `Vec`.
pub fn convert_par<T: Target>(src: &[u8], ty: Scalar, be: bool) -> Vec<T> {
    let n = src.len() / ty.size();
    let mut out = vec![T::default(); n];
    out.par_chunks_mut(CONVERT_CHUNK)
        .zip(src.par_chunks(CONVERT_CHUNK * ty.size()))
        .for_each(|(o, s)| convert_bytes(s, ty, be, o));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conversion_is_exact_and_saturates() {
        let src: Vec<u8> = [-1i64, 7, 1 << 40]
            .iter()
            .flat_map(|v| v.to_be_bytes())
            .collect();
        let mut out = [0u32; 3];
        convert_bytes(&src, Scalar::I64, true, &mut out);
        assert_eq!(out, [u32::MAX, 7, u32::MAX]);
        let f = 0.1f32;
        let mut o = [0f32; 1];
        convert_bytes(&f.to_le_bytes(), Scalar::F32, false, &mut o);
        assert_eq!(o[0].to_bits(), f.to_bits());
    }
}
