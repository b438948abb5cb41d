//! Data arrays attached to a mesh and the scalar field a render uses.
//!
//! [`DataArray`] keeps the values as the file stored them (`f32` and `f64`
//! without loss, integers widened to `i64`). [`select_field`] turns a
//! `--field` request (or its absence: the default-field rule of docs/conventions.md) into
//! a [`ScalarField`]: one `f64` per point or per cell, with its range.
//!
//! The default-field rule passes over VTK's bookkeeping arrays
//! ([`VTK_BOOKKEEPING_ARRAYS`]: `vtkGhostType`, `vtkOriginalCellIds`,
//! `vtkOriginalPointIds`), which hold flags and ids rather than data: the
//! rule runs over the other arrays first, and over all of them only when
//! it found nothing there. `--field` names any array.

use thiserror::Error;

pub use crate::mesh::data::{ArrayData, Association, DataArray};
use crate::mesh::Mesh;

/// The scalar field a render integrates.
#[derive(Clone, Debug, PartialEq)]
pub struct ScalarField {
    /// Display name, e.g. `Density` or `velocity:mag`.
    pub name: String,
    /// Point or cell values.
    pub association: Association,
    /// One value per point or per cell. Infinities are stored as NaN:
    /// every renderer treats a non-finite value as missing
    /// ([`ScalarField::new`]).
    pub values: Vec<f64>,
    /// Min and max of the finite values (`(0, 0)` when none).
    pub range: (f64, f64),
    /// Whether every value is finite (no NaN, no infinity): `range` is
    /// then the min and max of all of them ([`ScalarField::span`]).
    pub all_finite: bool,
}

impl ScalarField {
    /// The field of `values`, with its range and finiteness computed once
    /// (one pass), so that per-frame questions about the whole field
    /// ([`ScalarField::span`]) cost nothing.
    ///
    /// An infinite value becomes NaN, a missing value, as NaN is: a ray
    /// segment with a missing value at an end is empty in the reference,
    /// and the projected modes leave out the regions in front of and
    /// behind the boundary triangles holding one (README, "Bad values").
    /// No value the renderers could integrate saturates every ray near
    /// such a point (a clamped infinity did, in the reference), and the
    /// `f32` stages never see one.
    pub fn new(name: String, association: Association, mut values: Vec<f64>) -> ScalarField {
        for v in values.iter_mut().filter(|v| v.is_infinite()) {
            *v = f64::NAN;
        }
        let range = finite_range(&values);
        let all_finite = values.iter().all(|v| v.is_finite());
        ScalarField {
            name,
            association,
            values,
            range,
            all_finite,
        }
    }

    /// Min and max of every value, or `None` where some value is not
    /// finite.
    pub fn span(&self) -> Option<(f64, f64)> {
        self.all_finite.then_some(self.range)
    }
}

/// Errors selecting a field.
#[derive(Debug, Error, PartialEq)]
pub enum FieldError {
    #[error("no array named '{name}' (available: {available})")]
    NotFound { name: String, available: String },
    #[error("array '{name}' has {components} components; component {index} does not exist")]
    BadComponent {
        name: String,
        components: usize,
        index: usize,
    },
    #[error("bad field specification '{0}': expected NAME, point:NAME or cell:NAME, optionally with :mag, :x, :y, :z or :N")]
    BadSpec(String),
    #[error("array '{name}' has {got} tuples but the mesh has {want} {assoc}s")]
    WrongLength {
        name: String,
        got: usize,
        want: usize,
        assoc: &'static str,
    },
}

/// Which component of an array to use.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Component {
    /// The single component of a scalar array, or the magnitude of a vector.
    Auto,
    Magnitude,
    Index(usize),
}

/// A parsed `--field` value.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FieldSpec {
    pub association: Option<Association>,
    pub name: String,
    pub component: Component,
}

impl FieldSpec {
    /// Parses `NAME`, `point:NAME`, `cell:NAME`, each optionally followed by
    /// `:mag`, `:x|:y|:z` or `:N`. Names may contain `:`; only a known suffix
    /// and prefix are split off. Percent escapes in the name are decoded.
    pub fn parse(s: &str) -> Result<FieldSpec, FieldError> {
        let mut rest = s;
        let mut association = None;
        if let Some(r) = rest.strip_prefix("point:") {
            association = Some(Association::Point);
            rest = r;
        } else if let Some(r) = rest.strip_prefix("cell:") {
            association = Some(Association::Cell);
            rest = r;
        }
        let mut component = Component::Auto;
        if let Some((head, suffix)) = rest.rsplit_once(':') {
            let c = match suffix {
                "mag" | "magnitude" => Some(Component::Magnitude),
                "x" | "X" => Some(Component::Index(0)),
                "y" | "Y" => Some(Component::Index(1)),
                "z" | "Z" => Some(Component::Index(2)),
                n => n.parse::<usize>().ok().map(Component::Index),
            };
            if let Some(c) = c {
                if !head.is_empty() {
                    component = c;
                    rest = head;
                }
            }
        }
        if rest.is_empty() {
            return Err(FieldError::BadSpec(s.to_string()));
        }
        Ok(FieldSpec {
            association,
            name: percent_decode(rest),
            component,
        })
    }
}

/// Decodes `%XX` escapes (as VTK legacy files write names with spaces).
/// Malformed escapes are kept literally.
pub fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            let hex = std::str::from_utf8(&b[i + 1..i + 3]).ok();
            if let Some(v) = hex.and_then(|h| u8::from_str_radix(h, 16).ok()) {
                out.push(v);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

fn extract(
    arr: &DataArray,
    assoc: Association,
    component: Component,
) -> Result<ScalarField, FieldError> {
    let n = arr.tuples();
    let (values, name): (Vec<f64>, String) = match component {
        Component::Index(k) if k >= arr.components => {
            return Err(FieldError::BadComponent {
                name: arr.name.clone(),
                components: arr.components,
                index: k,
            })
        }
        Component::Index(k) if arr.components > 1 => (
            (0..n).map(|i| arr.component(i, k)).collect(),
            format!("{}:{k}", arr.name),
        ),
        Component::Magnitude if arr.components > 1 => (
            (0..n).map(|i| arr.magnitude(i)).collect(),
            format!("{}:mag", arr.name),
        ),
        Component::Auto if arr.components > 1 => (
            (0..n).map(|i| arr.magnitude(i)).collect(),
            format!("{}:mag", arr.name),
        ),
        _ => (
            (0..n).map(|i| arr.component(i, 0)).collect(),
            arr.name.clone(),
        ),
    };
    Ok(ScalarField::new(name, assoc, values))
}

/// Min and max of the finite values, `(0, 0)` when there are none.
pub fn finite_range(values: &[f64]) -> (f64, f64) {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for &v in values {
        if v.is_finite() {
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    if lo <= hi {
        (lo, hi)
    } else {
        (0.0, 0.0)
    }
}

/// Selects the scalar field: the named one, or by the default rule of
/// docs/conventions.md when `spec` is `None`. Returns `Ok(None)` when the mesh has no
/// usable array (render the geometry with a constant scalar).
pub fn select_field(
    mesh: &Mesh,
    spec: Option<&FieldSpec>,
) -> Result<Option<ScalarField>, FieldError> {
    let field = match spec {
        Some(spec) => Some(select_named(mesh, spec)?),
        None => select_default(mesh)?,
    };
    if let Some(f) = &field {
        let want = match f.association {
            Association::Point => mesh.points.len(),
            Association::Cell => mesh.cells.len(),
        };
        if f.values.len() != want {
            return Err(FieldError::WrongLength {
                name: f.name.clone(),
                got: f.values.len(),
                want,
                assoc: f.association.as_str(),
            });
        }
    }
    Ok(field)
}

fn select_named(mesh: &Mesh, spec: &FieldSpec) -> Result<ScalarField, FieldError> {
    let point = mesh.point_data.iter().find(|a| a.name == spec.name);
    let cell = mesh.cell_data.iter().find(|a| a.name == spec.name);
    let found = match spec.association {
        Some(Association::Point) => point.map(|a| (a, Association::Point)),
        Some(Association::Cell) => cell.map(|a| (a, Association::Cell)),
        None => point
            .map(|a| (a, Association::Point))
            .or(cell.map(|a| (a, Association::Cell))),
    };
    match found {
        Some((arr, assoc)) => extract(arr, assoc, spec.component),
        None => {
            let mut names: Vec<String> = mesh
                .point_data
                .iter()
                .map(|a| format!("point:{}", a.name))
                .chain(mesh.cell_data.iter().map(|a| format!("cell:{}", a.name)))
                .collect();
            if names.is_empty() {
                names.push("none".into());
            }
            Err(FieldError::NotFound {
                name: spec.name.clone(),
                available: names.join(", "),
            })
        }
    }
}

/// Arrays VTK adds for its own bookkeeping (ghost flags, the ids of cells
/// and points before a filter): the default-field rule takes them only
/// when the mesh has no other array it could take.
pub const VTK_BOOKKEEPING_ARRAYS: [&str; 3] =
    ["vtkGhostType", "vtkOriginalCellIds", "vtkOriginalPointIds"];

/// Whether `name` is one of [`VTK_BOOKKEEPING_ARRAYS`].
pub fn is_vtk_bookkeeping(name: &str) -> bool {
    VTK_BOOKKEEPING_ARRAYS.contains(&name)
}

fn select_default(mesh: &Mesh) -> Result<Option<ScalarField>, FieldError> {
    match default_among(mesh, |a| !is_vtk_bookkeeping(&a.name))? {
        Some(f) => Ok(Some(f)),
        None => default_among(mesh, |_| true),
    }
}

/// The default-field rule over the arrays `usable` accepts.
fn default_among(
    mesh: &Mesh,
    usable: fn(&DataArray) -> bool,
) -> Result<Option<ScalarField>, FieldError> {
    use Association::{Cell, Point};
    let pd = &mesh.point_data;
    let cd = &mesh.cell_data;
    // (1) active point scalars with one component
    if let Some(name) = &mesh.active_point_scalars {
        if let Some(a) = pd
            .iter()
            .find(|a| &a.name == name && a.components == 1 && usable(a))
        {
            return extract(a, Point, Component::Auto).map(Some);
        }
    }
    type Rule<'a> = (&'a Vec<DataArray>, Association, fn(&DataArray) -> bool);
    let rules: [Rule; 6] = [
        (pd, Point, |a| a.data.is_float() && a.components == 1),
        (cd, Cell, |a| a.data.is_float() && a.components == 1),
        (pd, Point, |a| a.data.is_float() && a.components > 1),
        (cd, Cell, |a| a.data.is_float() && a.components > 1),
        // (6) the first integer array, point before cell
        (pd, Point, |a| !a.data.is_float()),
        (cd, Cell, |a| !a.data.is_float()),
    ];
    for (arrays, assoc, pred) in rules {
        if let Some(a) = arrays.iter().find(|a| usable(a) && pred(a)) {
            return extract(a, assoc, Component::Auto).map(Some);
        }
    }
    Ok(None)
}

/// Averages a cell field to points (`--cell-to-point`): each point gets the
/// mean of the cells that use it; points used by no cell get 0.
pub fn cell_to_point(mesh: &Mesh, field: &ScalarField) -> ScalarField {
    if field.association == Association::Point {
        return field.clone();
    }
    let mut sum = vec![0.0f64; mesh.points.len()];
    let mut cnt = vec![0u32; mesh.points.len()];
    for c in 0..mesh.cells.len() {
        let v = field.values[c];
        for &n in mesh.cells.nodes(c) {
            sum[n as usize] += v;
            cnt[n as usize] += 1;
        }
    }
    let values: Vec<f64> = sum
        .iter()
        .zip(&cnt)
        .map(|(s, &n)| if n > 0 { s / n as f64 } else { 0.0 })
        .collect();
    ScalarField::new(field.name.clone(), Association::Point, values)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn span_is_every_value_or_none() {
        let f = |v: Vec<f64>| ScalarField::new("f".into(), Association::Point, v);
        assert_eq!(f(vec![2.0, -1.0, 5.0]).span(), Some((-1.0, 5.0)));
        assert_eq!(f(vec![]).span(), Some((0.0, 0.0)));
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let g = f(vec![2.0, bad, 5.0]);
            assert_eq!(g.range, (2.0, 5.0), "the finite range stays");
            assert_eq!(g.span(), None, "{bad}");
            // Every non-finite value is stored as a missing one, NaN.
            assert!(g.values[1].is_nan() && g.values[0] == 2.0, "{bad}");
        }
    }

    #[test]
    fn parse_specs() {
        let s = FieldSpec::parse("point:velocity:mag").unwrap();
        assert_eq!(s.association, Some(Association::Point));
        assert_eq!(s.name, "velocity");
        assert_eq!(s.component, Component::Magnitude);
        let s = FieldSpec::parse("Nodal%20Stress:2").unwrap();
        assert_eq!(s.name, "Nodal Stress");
        assert_eq!(s.component, Component::Index(2));
        let s = FieldSpec::parse("a:b").unwrap();
        assert_eq!(s.name, "a:b");
        assert!(FieldSpec::parse("cell:").is_err());
    }

    #[test]
    fn percent() {
        assert_eq!(percent_decode("a%20b%2"), "a b%2");
        assert_eq!(percent_decode("%"), "%");
    }
}
