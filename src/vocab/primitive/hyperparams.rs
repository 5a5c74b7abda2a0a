//! Primitive fitting settings, checked once.

use crate::params::{InvalidField, Params};
use crate::vocab::knn::MAX_LATENT_DIMS;

/// Fitting settings; [`FitParams::check`] validates them.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FitParams {
    /// Share of the poses' variance the latent space keeps.
    pub variance: f64,
    /// At least this many dimensions, whatever the variance: a dimension
    /// that opens a loop (the wrist turning while waving) can carry 2 or 3%
    /// of the variance, and without it the way out and the way back fall
    /// on one line where the field cancels out.
    pub min_dims: usize,
    pub max_dims: usize,
    /// Training poses consulted by the gradient field and progress.
    pub neighbors: usize,
}

impl Default for FitParams {
    fn default() -> Self {
        FitParams { variance: 0.95, min_dims: 4, max_dims: 8, neighbors: 8 }
    }
}

/// Settings that passed [`FitParams::check`].
#[derive(Clone, Debug, PartialEq)]
pub struct ValidFitParams(pub(crate) FitParams);

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum FitParamsError {
    #[error("variance: the share of pose variance kept must lie in (0, 1], not {0}")]
    Variance(f64),
    #[error("min_dims: the fewest latent dimensions must be at least 1")]
    MinDims,
    #[error("max_dims: the most latent dimensions must be between the fewest ({min}) and {MAX_LATENT_DIMS}, not {max}")]
    MaxDims { min: usize, max: usize },
    #[error("neighbors: the field needs at least one neighbour")]
    Neighbors,
}

impl InvalidField for FitParamsError {
    fn field(&self) -> &'static str {
        match self {
            FitParamsError::Variance(_) => "variance",
            FitParamsError::MinDims => "min_dims",
            FitParamsError::MaxDims { .. } => "max_dims",
            FitParamsError::Neighbors => "neighbors",
        }
    }
}

impl FitParams {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn variance(mut self, share: f64) -> Self {
        self.variance = share;
        self
    }

    pub fn min_dims(mut self, d: usize) -> Self {
        self.min_dims = d;
        self
    }

    pub fn max_dims(mut self, d: usize) -> Self {
        self.max_dims = d;
        self
    }

    pub fn neighbors(mut self, k: usize) -> Self {
        self.neighbors = k;
        self
    }
}

impl Params for FitParams {
    type Valid = ValidFitParams;
    type Error = FitParamsError;

    fn check(&self) -> Result<ValidFitParams, FitParamsError> {
        if !(self.variance > 0.0 && self.variance <= 1.0) {
            return Err(FitParamsError::Variance(self.variance));
        }
        if self.min_dims == 0 {
            return Err(FitParamsError::MinDims);
        }
        if self.max_dims < self.min_dims || self.max_dims > MAX_LATENT_DIMS {
            return Err(FitParamsError::MaxDims { min: self.min_dims, max: self.max_dims });
        }
        if self.neighbors == 0 {
            return Err(FitParamsError::Neighbors);
        }
        Ok(ValidFitParams(self.clone()))
    }
}

impl ValidFitParams {
    pub fn params(&self) -> &FitParams {
        &self.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_rule_has_its_own_error() {
        assert!(FitParams::new().check().is_ok());
        assert_eq!(FitParams::new().variance(0.0).check(), Err(FitParamsError::Variance(0.0)));
        assert_eq!(FitParams::new().min_dims(0).check(), Err(FitParamsError::MinDims));
        assert_eq!(FitParams::new().min_dims(4).max_dims(3).check(), Err(FitParamsError::MaxDims { min: 4, max: 3 }));
        assert_eq!(FitParams::new().max_dims(13).check(), Err(FitParamsError::MaxDims { min: 4, max: 13 }));
        assert_eq!(FitParams::new().neighbors(0).check(), Err(FitParamsError::Neighbors));
    }
}
