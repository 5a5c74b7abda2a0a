//! Segmentation settings, checked once.

use crate::params::{InvalidField, Params};

/// How to find segment boundaries.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// Kinematic centroids: a segment ends when the limbs have swung away
    /// from its first posture and come back.
    Kcs,
    /// Zero-velocity crossings: a segment ends where the summed squared
    /// joint velocity dips.
    Zvc,
}

/// Segmentation settings; [`SegmentParams::check`] validates them.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SegmentParams {
    pub method: Method,
    pub min_length_s: f64,
    pub max_length_s: f64,
    pub smoothing_s: f64,
    /// KCS: how close to its start the centroid must come back, as a share
    /// of its largest excursion.
    pub return_share: f64,
    /// KCS: a return counts as retracing the way out, and the swing is cut
    /// at its turn, when it keeps closer than this share of its reach to
    /// the outward path (joint space).
    pub retrace_share: f64,
    /// KCS: the smallest excursion that counts as a swing, meters.
    pub min_excursion_m: f64,
    /// ZVC: how deep an energy dip must be, as a share of the lower of the
    /// peaks beside it.
    pub dip_share: f64,
}

impl Default for SegmentParams {
    fn default() -> Self {
        SegmentParams {
            method: Method::Kcs,
            min_length_s: 0.2,
            max_length_s: 5.0,
            smoothing_s: 0.05,
            return_share: 0.5,
            retrace_share: 0.07,
            min_excursion_m: 0.05,
            dip_share: 0.5,
        }
    }
}

/// Settings that passed [`SegmentParams::check`].
#[derive(Clone, Debug, PartialEq)]
pub struct ValidSegmentParams(pub(crate) SegmentParams);

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum SegmentParamsError {
    #[error("min_length_s: the shortest segment must be a positive number of seconds, not {0}")]
    MinLength(f64),
    #[error("max_length_s: the longest segment ({max} s) must be at least twice the shortest ({min} s)")]
    MaxLength { min: f64, max: f64 },
    #[error("smoothing_s: the smoothing must be a non-negative number of seconds, not {0}")]
    Smoothing(f64),
    #[error("return_share: the return share must lie in (0, 1), not {0}")]
    ReturnShare(f64),
    #[error("retrace_share: the retrace share must lie in (0, 1), not {0}")]
    RetraceShare(f64),
    #[error("min_excursion_m: the smallest swing must be a non-negative number of meters, not {0}")]
    MinExcursion(f64),
    #[error("dip_share: the dip share must lie in (0, 1), not {0}")]
    DipShare(f64),
}

impl InvalidField for SegmentParamsError {
    fn field(&self) -> &'static str {
        match self {
            SegmentParamsError::MinLength(_) => "min_length_s",
            SegmentParamsError::MaxLength { .. } => "max_length_s",
            SegmentParamsError::Smoothing(_) => "smoothing_s",
            SegmentParamsError::ReturnShare(_) => "return_share",
            SegmentParamsError::RetraceShare(_) => "retrace_share",
            SegmentParamsError::MinExcursion(_) => "min_excursion_m",
            SegmentParamsError::DipShare(_) => "dip_share",
        }
    }
}

impl SegmentParams {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn method(mut self, method: Method) -> Self {
        self.method = method;
        self
    }

    pub fn min_length_s(mut self, seconds: f64) -> Self {
        self.min_length_s = seconds;
        self
    }

    pub fn max_length_s(mut self, seconds: f64) -> Self {
        self.max_length_s = seconds;
        self
    }

    pub fn smoothing_s(mut self, seconds: f64) -> Self {
        self.smoothing_s = seconds;
        self
    }

    pub fn return_share(mut self, share: f64) -> Self {
        self.return_share = share;
        self
    }

    pub fn retrace_share(mut self, share: f64) -> Self {
        self.retrace_share = share;
        self
    }

    pub fn min_excursion_m(mut self, meters: f64) -> Self {
        self.min_excursion_m = meters;
        self
    }

    pub fn dip_share(mut self, share: f64) -> Self {
        self.dip_share = share;
        self
    }
}

impl Params for SegmentParams {
    type Valid = ValidSegmentParams;
    type Error = SegmentParamsError;

    fn check(&self) -> Result<ValidSegmentParams, SegmentParamsError> {
        let p = self;
        let unit = |x: f64| x > 0.0 && x < 1.0;
        if !(p.min_length_s > 0.0 && p.min_length_s.is_finite()) {
            return Err(SegmentParamsError::MinLength(p.min_length_s));
        }
        // Twice, so a long segment can always be split into two legal ones.
        if !(p.max_length_s >= 2.0 * p.min_length_s && p.max_length_s.is_finite()) {
            return Err(SegmentParamsError::MaxLength { min: p.min_length_s, max: p.max_length_s });
        }
        if !(p.smoothing_s >= 0.0 && p.smoothing_s.is_finite()) {
            return Err(SegmentParamsError::Smoothing(p.smoothing_s));
        }
        if !unit(p.return_share) {
            return Err(SegmentParamsError::ReturnShare(p.return_share));
        }
        if !unit(p.retrace_share) {
            return Err(SegmentParamsError::RetraceShare(p.retrace_share));
        }
        if !(p.min_excursion_m >= 0.0 && p.min_excursion_m.is_finite()) {
            return Err(SegmentParamsError::MinExcursion(p.min_excursion_m));
        }
        if !unit(p.dip_share) {
            return Err(SegmentParamsError::DipShare(p.dip_share));
        }
        Ok(ValidSegmentParams(self.clone()))
    }
}

impl ValidSegmentParams {
    pub fn params(&self) -> &SegmentParams {
        &self.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_rule_has_its_own_error() {
        let p = SegmentParams::new();
        assert!(p.check().is_ok());
        assert_eq!(p.clone().min_length_s(0.0).check(), Err(SegmentParamsError::MinLength(0.0)));
        assert_eq!(p.clone().max_length_s(0.1).check(), Err(SegmentParamsError::MaxLength { min: 0.2, max: 0.1 }));
        assert_eq!(p.clone().smoothing_s(-1.0).check(), Err(SegmentParamsError::Smoothing(-1.0)));
        assert_eq!(p.clone().return_share(1.0).check(), Err(SegmentParamsError::ReturnShare(1.0)));
        assert_eq!(p.clone().retrace_share(0.0).check(), Err(SegmentParamsError::RetraceShare(0.0)));
        assert!(p.clone().min_excursion_m(f64::NAN).check().unwrap_err().to_string().contains("NaN"));
        assert_eq!(p.dip_share(0.0).check(), Err(SegmentParamsError::DipShare(0.0)));
    }
}
