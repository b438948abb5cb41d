//! `POINT_DATA` / `CELL_DATA` attributes and `FIELD` blocks.
//!
//! After `POINT_DATA n` or `CELL_DATA n` a file lists attributes, each a
//! keyword line followed by its values:
//! `SCALARS name type [numComp]` (then an optional `LOOKUP_TABLE name` line),
//! `VECTORS`/`NORMALS name type` (3 components), `TENSORS name type` (9),
//! `TENSORS6 name type` (6), `TEXTURE_COORDINATES name dim type`,
//! `COLOR_SCALARS name nValues` (floats in ASCII, bytes in binary),
//! `GLOBAL_IDS`/`PEDIGREE_IDS name type`, `LOOKUP_TABLE name size` (a colour
//! table: skipped) and `FIELD name nArrays`, whose arrays each carry their own
//! `name numComp numTuples type` line. `METADATA` blocks may follow any array.
//! Names are percent-decoded (`%20` is a space).

use super::tokens::{show, Cursor, ValueType};
use crate::field::{percent_decode, ArrayData, DataArray};
use crate::io::IoError;

/// What one attribute section produced.
pub(crate) enum Attribute {
    /// A `SCALARS` array (candidate for the active scalars).
    Scalars(DataArray),
    /// Other arrays (vectors, tensors, field arrays, ...).
    Arrays(Vec<DataArray>),
    /// Nothing to keep (a lookup table).
    Skipped,
}

/// Whether `kw` (upper case) starts an attribute section.
pub(crate) fn is_attribute(kw: &str) -> bool {
    matches!(
        kw,
        "SCALARS"
            | "VECTORS"
            | "NORMALS"
            | "TENSORS"
            | "TENSORS6"
            | "TEXTURE_COORDINATES"
            | "COLOR_SCALARS"
            | "GLOBAL_IDS"
            | "PEDIGREE_IDS"
            | "LOOKUP_TABLE"
            | "FIELD"
    )
}

fn name(cur: &mut Cursor<'_>, kw: &str) -> Result<String, IoError> {
    let t = cur.token(&format!("the {kw} name"))?;
    Ok(percent_decode(&String::from_utf8_lossy(t)))
}

fn read_array(
    cur: &mut Cursor<'_>,
    name: String,
    comps: usize,
    tuples: usize,
    ty: ValueType,
) -> Result<DataArray, IoError> {
    if comps == 0 {
        return Err(cur.err(format!("array '{name}' has 0 components")));
    }
    let n = comps
        .checked_mul(tuples)
        .ok_or_else(|| cur.err(format!("array '{name}': size overflows")))?;
    let (data, _) = cur.read_values(n, ty, &format!("array '{name}'"))?;
    Ok(DataArray {
        name,
        components: comps,
        data,
        vtk_type: ty.vtk_name().to_string(),
    })
}

/// Reads one attribute section whose keyword `kw` (upper case) was just read;
/// `tuples` is the count from `POINT_DATA`/`CELL_DATA`.
pub(crate) fn read_attribute(
    cur: &mut Cursor<'_>,
    kw: &str,
    tuples: usize,
) -> Result<Attribute, IoError> {
    match kw {
        "SCALARS" => {
            let name = name(cur, kw)?;
            let ty = cur.value_type()?;
            let mut comps = 1;
            if let Some(t) = cur.token_on_line() {
                comps = std::str::from_utf8(t)
                    .ok()
                    .and_then(|s| s.parse::<usize>().ok())
                    .filter(|&c| (1..=1024).contains(&c))
                    .ok_or_else(|| {
                        cur.err(format!(
                            "SCALARS '{name}': invalid component count '{}'",
                            show(t)
                        ))
                    })?;
            }
            if cur.accept_keyword("LOOKUP_TABLE") {
                cur.token("the lookup table name")?;
            }
            Ok(Attribute::Scalars(read_array(
                cur, name, comps, tuples, ty,
            )?))
        }
        "VECTORS" | "NORMALS" | "TENSORS" | "TENSORS6" | "GLOBAL_IDS" | "PEDIGREE_IDS" => {
            let comps = match kw {
                "VECTORS" | "NORMALS" => 3,
                "TENSORS" => 9,
                "TENSORS6" => 6,
                _ => 1,
            };
            let name = name(cur, kw)?;
            let ty = cur.value_type()?;
            Ok(Attribute::Arrays(vec![read_array(
                cur, name, comps, tuples, ty,
            )?]))
        }
        "TEXTURE_COORDINATES" => {
            let name = name(cur, kw)?;
            let dim = cur.count("the texture dimension")?;
            if !(1..=3).contains(&dim) {
                return Err(cur.err(format!(
                    "TEXTURE_COORDINATES '{name}': dimension {dim} not in 1..=3"
                )));
            }
            let ty = cur.value_type()?;
            Ok(Attribute::Arrays(vec![read_array(
                cur, name, dim, tuples, ty,
            )?]))
        }
        "COLOR_SCALARS" => {
            let name = name(cur, kw)?;
            let comps = cur.count("the colour component count")?;
            if !(1..=4).contains(&comps) {
                return Err(cur.err(format!(
                    "COLOR_SCALARS '{name}': {comps} components not in 1..=4"
                )));
            }
            let ty = if cur.is_binary() {
                ValueType::U8
            } else {
                ValueType::F32
            };
            Ok(Attribute::Arrays(vec![read_array(
                cur, name, comps, tuples, ty,
            )?]))
        }
        "LOOKUP_TABLE" => {
            let name = name(cur, kw)?;
            let size = cur.count("the lookup table size")?;
            let ty = if cur.is_binary() {
                ValueType::U8
            } else {
                ValueType::F32
            };
            read_array(cur, name, 4, size, ty)?;
            Ok(Attribute::Skipped)
        }
        "FIELD" => Ok(Attribute::Arrays(read_field(cur, Some(tuples))?)),
        _ => Err(cur.err(format!("unknown attribute keyword '{kw}'"))),
    }
}

/// Reads a `FIELD name nArrays` block (keyword already read). With
/// `tuples = Some(n)` (point or cell data) every array must have `n` tuples;
/// dataset-level blocks (`None`) may hold arrays of any length.
pub(crate) fn read_field(
    cur: &mut Cursor<'_>,
    tuples: Option<usize>,
) -> Result<Vec<DataArray>, IoError> {
    cur.token("the FIELD name")?;
    let n = cur.count("the FIELD array count")?;
    if n > cur.remaining() {
        return Err(cur.err(format!("FIELD claims {n} arrays, more than the bytes left")));
    }
    let mut arrays = Vec::new();
    for _ in 0..n {
        while cur.accept_keyword("METADATA") {
            cur.skip_metadata();
        }
        let raw = cur.token("a FIELD array name")?;
        if raw == b"NULL_ARRAY" {
            continue;
        }
        let name = percent_decode(&String::from_utf8_lossy(raw));
        let comps = cur.count("the component count")?;
        let count = cur.count("the tuple count")?;
        let tt = cur.token("a data type")?;
        let ty = ValueType::parse(tt).ok_or_else(|| {
            cur.err(format!(
                "FIELD array '{name}': unsupported data type '{}' (string arrays are not read)",
                show(tt)
            ))
        })?;
        if let Some(m) = tuples {
            if count != m {
                return Err(cur.err(format!(
                    "FIELD array '{name}' has {count} tuples, the data section has {m}"
                )));
            }
        }
        arrays.push(read_array(cur, name, comps, count, ty)?);
    }
    Ok(arrays)
}

/// Keeps the tuples of `arr` whose flag in `keep` is set.
pub(crate) fn filter_tuples(arr: DataArray, keep: &[bool]) -> DataArray {
    let k = arr.components.max(1);
    fn pick<T: Copy>(v: &[T], keep: &[bool], k: usize) -> Vec<T> {
        v.chunks_exact(k)
            .zip(keep)
            .filter(|(_, &f)| f)
            .flat_map(|(c, _)| c.iter().copied())
            .collect()
    }
    let data = match &arr.data {
        ArrayData::F32(v) => ArrayData::F32(pick(v, keep, k)),
        ArrayData::F64(v) => ArrayData::F64(pick(v, keep, k)),
        ArrayData::Int(v) => ArrayData::Int(pick(v, keep, k)),
    };
    DataArray { data, ..arr }
}
