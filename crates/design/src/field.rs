//! Checks of a file's numeric fields, in one wording for every file the
//! project reads (device models, linkage files, scenes): `name = value
//! must be finite and > 0`.

/// `v`, where the field `name` is finite and > 0.
///
/// ```
/// use twoport_design::field::positive;
/// assert_eq!(positive("period_s", 1e-3), Ok(1e-3));
/// assert_eq!(positive("period_s", 0.0).unwrap_err(), "period_s = 0 must be finite and > 0");
/// ```
pub fn positive(name: &str, v: f64) -> Result<f64, String> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(format!("{name} = {v} must be finite and > 0"))
    }
}

/// `v`, where the field `name` is finite and >= 0.
pub fn non_negative(name: &str, v: f64) -> Result<f64, String> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(format!("{name} = {v} must be finite and >= 0"))
    }
}
