//! Parsers for CLI values (`--size WxH`, `--range LO,HI`, `--background R,G,B`,
//! `--frames A..B`)
//! that reject NaN and nonsense with a usage error.

use zoovr::render::modes::preint_tables::{TableKind, TableSpec};

/// Parses `WxH` (e.g. `512x512`); both positive and at most 16384.
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WxH, e.g. 512x512, got '{s}'"))?;
    let w: u32 = w
        .trim()
        .parse()
        .map_err(|_| format!("bad width in '{s}'"))?;
    let h: u32 = h
        .trim()
        .parse()
        .map_err(|_| format!("bad height in '{s}'"))?;
    if w == 0 || h == 0 {
        return Err(format!("image size must be positive, got '{s}'"));
    }
    if w > 16384 || h > 16384 {
        return Err(format!(
            "image size '{s}' is larger than 16384 in one dimension"
        ));
    }
    Ok((w, h))
}

/// Parses `LO,HI` with finite LO < HI.
pub fn parse_range(s: &str) -> Result<(f64, f64), String> {
    let v = parse_floats(s)?;
    if v.len() != 2 {
        return Err(format!("expected LO,HI, got '{s}'"));
    }
    if v[0] >= v[1] {
        return Err(format!("empty range '{s}': LO must be less than HI"));
    }
    Ok((v[0], v[1]))
}

/// Parses `R,G,B` with components in [0, 1].
pub fn parse_rgb(s: &str) -> Result<[f32; 3], String> {
    let v = parse_floats(s)?;
    if v.len() != 3 || v.iter().any(|c| !(0.0..=1.0).contains(c)) {
        return Err(format!("expected R,G,B with values in [0,1], got '{s}'"));
    }
    Ok([v[0] as f32, v[1] as f32, v[2] as f32])
}

/// Parses a finite float.
pub fn parse_finite(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("not a number: '{s}'"))?;
    if !v.is_finite() {
        return Err(format!("not a finite number: '{s}'"));
    }
    Ok(v)
}

/// Parses a positive finite float.
pub fn parse_positive(s: &str) -> Result<f64, String> {
    let v = parse_finite(s)?;
    if v <= 0.0 {
        return Err(format!("must be positive: '{s}'"));
    }
    Ok(v)
}

/// Parses `--table N`: a whole number, at least the library's smallest
/// table ([`TableSpec::check_small`]); what an adapter can hold is checked
/// when it draws.
pub fn parse_table_size(s: &str) -> Result<u32, String> {
    let n: u32 = s
        .trim()
        .parse()
        .map_err(|_| format!("not a whole number of samples: '{s}'"))?;
    TableSpec::check_small(TableKind::Cube, Some(n)).map_err(|e| e.to_string())?;
    Ok(n)
}

/// Parses a comma-separated list of finite floats.
pub fn parse_floats(s: &str) -> Result<Vec<f64>, String> {
    s.split(',').map(parse_finite).collect()
}

/// Parses `A..B` (inclusive, A <= B) or a single frame `A`.
pub fn parse_frames(s: &str) -> Result<(usize, usize), String> {
    let bad = || format!("expected A..B (inclusive frame indices, e.g. 0..9), got '{s}'");
    let (a, b) = match s.split_once("..") {
        Some((a, b)) => (a, b.strip_prefix('=').unwrap_or(b)),
        None => (s, s),
    };
    let a: usize = a.trim().parse().map_err(|_| bad())?;
    let b: usize = b.trim().parse().map_err(|_| bad())?;
    if a > b {
        return Err(format!(
            "empty frame range '{s}': A must not be greater than B"
        ));
    }
    Ok((a, b))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_rejects() {
        assert_eq!(parse_size("640x480"), Ok((640, 480)));
        assert!(parse_size("0x10").is_err());
        assert!(parse_size("10").is_err());
        assert_eq!(parse_range("-1,2.5"), Ok((-1.0, 2.5)));
        assert!(parse_range("1,1").is_err());
        assert!(parse_range("nan,1").is_err());
        assert_eq!(parse_rgb("1,0,0.5"), Ok([1.0, 0.0, 0.5]));
        assert!(parse_rgb("2,0,0").is_err());
        assert_eq!(parse_frames("2..5"), Ok((2, 5)));
        assert_eq!(parse_frames("3"), Ok((3, 3)));
        assert!(parse_frames("5..2").is_err());
        assert!(parse_frames("a..2").is_err());
    }
}
