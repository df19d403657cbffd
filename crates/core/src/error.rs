//! The error every stage returns for a bad parameter: it names the stage, the parameter,
//! the value and the rule it broke, so a user can fix the input without reading code.

use thiserror::Error;

/// An invalid stage parameter.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{stage}: parameter `{param}` = {value} is invalid: {rule}")]
pub struct ParamError {
    /// The stage that refused the parameter, e.g. `"resonator"`.
    pub stage: &'static str,
    /// The parameter name with its unit, e.g. `"f0_hz"`.
    pub param: &'static str,
    /// The offending value, formatted.
    pub value: String,
    /// The rule the value broke, e.g. `"must be finite and > 0"`.
    pub rule: String,
}

/// Result of building a stage.
pub type ParamResult<T> = Result<T, ParamError>;

impl ParamError {
    /// Builds an error from its parts.
    pub fn new(
        stage: &'static str,
        param: &'static str,
        value: impl ToString,
        rule: impl Into<String>,
    ) -> Self {
        Self {
            stage,
            param,
            value: value.to_string(),
            rule: rule.into(),
        }
    }
}

/// Requires a finite value.
pub fn finite(stage: &'static str, param: &'static str, v: f64) -> ParamResult<f64> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(ParamError::new(stage, param, v, "must be a finite number"))
    }
}

/// Requires a finite value strictly greater than zero.
pub fn positive(stage: &'static str, param: &'static str, v: f64) -> ParamResult<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(ParamError::new(stage, param, v, "must be finite and > 0"))
    }
}

/// Requires a finite value greater than or equal to zero.
pub fn non_negative(stage: &'static str, param: &'static str, v: f64) -> ParamResult<f64> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(ParamError::new(stage, param, v, "must be finite and >= 0"))
    }
}

/// Requires `0 < f < fs/2` (a frequency strictly inside the Nyquist band).
pub fn below_nyquist(
    stage: &'static str,
    param: &'static str,
    f_hz: f64,
    fs_hz: f64,
) -> ParamResult<f64> {
    if f_hz.is_finite() && f_hz > 0.0 && f_hz < 0.5 * fs_hz {
        Ok(f_hz)
    } else {
        Err(ParamError::new(
            stage,
            param,
            f_hz,
            format!(
                "must be finite, > 0 and below Nyquist (fs/2 = {} Hz)",
                0.5 * fs_hz
            ),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn message_names_stage_param_value_rule() {
        let e = positive("resonator", "q", -3.0).unwrap_err();
        let m = e.to_string();
        assert!(
            m.contains("resonator") && m.contains("`q`") && m.contains("-3") && m.contains("> 0")
        );
        assert!(finite("x", "y", f64::NAN).is_err());
        assert!(positive("x", "y", f64::INFINITY).is_err());
        assert!(non_negative("x", "y", 0.0).is_ok());
        assert!(below_nyquist("lpf", "cutoff_hz", 500.0, 1000.0).is_err());
        assert!(below_nyquist("lpf", "cutoff_hz", 499.0, 1000.0).is_ok());
    }
}
