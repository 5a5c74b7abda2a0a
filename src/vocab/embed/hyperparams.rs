//! ST-Isomap settings, checked once.

use crate::params::{InvalidField, Params};
use crate::vocab::eigen::EigenMethod;

/// ST-Isomap settings; [`EmbedParams::check`] validates them.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EmbedParams {
    pub neighbors: usize,
    pub dims: usize,
    pub resample: usize,
    /// Adjacent temporal neighbours (consecutive segments of a take):
    /// their distance is divided by this.
    pub c_atn: f64,
    /// Common temporal neighbours (neighbouring segments whose successors,
    /// or predecessors, are neighbours too): their distance is divided by
    /// this.
    pub c_ctn: f64,
    /// False for plain Isomap: no temporal edges, no shrinking.
    pub temporal: bool,
    #[serde(skip)]
    pub eigen: EigenMethod,
}

impl Default for EmbedParams {
    fn default() -> Self {
        EmbedParams {
            neighbors: 8,
            dims: 8,
            resample: 20,
            c_atn: 6.0,
            c_ctn: 3.0,
            temporal: true,
            eigen: EigenMethod::Auto,
        }
    }
}

/// Settings that passed [`EmbedParams::check`].
#[derive(Clone, Debug, PartialEq)]
pub struct ValidEmbedParams(pub(crate) EmbedParams);

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum EmbedParamsError {
    #[error("neighbors: the number of neighbours must be at least 1")]
    Neighbors,
    #[error("dims: the number of embedding dimensions must be at least 1")]
    Dims,
    #[error("resample: segments must be resampled to at least 2 frames, not {0}")]
    Resample(usize),
    #[error("c_atn: must be a number of at least 1 (1 leaves distances as they are), not {0}")]
    Atn(f64),
    #[error("c_ctn: must be a number of at least 1 (1 leaves distances as they are), not {0}")]
    Ctn(f64),
}

impl InvalidField for EmbedParamsError {
    fn field(&self) -> &'static str {
        match self {
            EmbedParamsError::Neighbors => "neighbors",
            EmbedParamsError::Dims => "dims",
            EmbedParamsError::Resample(_) => "resample",
            EmbedParamsError::Atn(_) => "c_atn",
            EmbedParamsError::Ctn(_) => "c_ctn",
        }
    }
}

impl EmbedParams {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn neighbors(mut self, k: usize) -> Self {
        self.neighbors = k;
        self
    }

    pub fn dims(mut self, d: usize) -> Self {
        self.dims = d;
        self
    }

    pub fn resample(mut self, frames: usize) -> Self {
        self.resample = frames;
        self
    }

    pub fn c_atn(mut self, c: f64) -> Self {
        self.c_atn = c;
        self
    }

    pub fn c_ctn(mut self, c: f64) -> Self {
        self.c_ctn = c;
        self
    }

    /// Plain Isomap (`false`) or spatio-temporal (`true`, the default).
    pub fn temporal(mut self, temporal: bool) -> Self {
        self.temporal = temporal;
        self
    }

    pub fn eigen(mut self, method: EigenMethod) -> Self {
        self.eigen = method;
        self
    }
}

impl Params for EmbedParams {
    type Valid = ValidEmbedParams;
    type Error = EmbedParamsError;

    fn check(&self) -> Result<ValidEmbedParams, EmbedParamsError> {
        let p = self;
        if p.neighbors == 0 {
            return Err(EmbedParamsError::Neighbors);
        }
        if p.dims == 0 {
            return Err(EmbedParamsError::Dims);
        }
        if p.resample < 2 {
            return Err(EmbedParamsError::Resample(p.resample));
        }
        if !(p.c_atn >= 1.0 && p.c_atn.is_finite()) {
            return Err(EmbedParamsError::Atn(p.c_atn));
        }
        if !(p.c_ctn >= 1.0 && p.c_ctn.is_finite()) {
            return Err(EmbedParamsError::Ctn(p.c_ctn));
        }
        Ok(ValidEmbedParams(self.clone()))
    }
}

impl ValidEmbedParams {
    pub fn params(&self) -> &EmbedParams {
        &self.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_rule_has_its_own_error() {
        let p = EmbedParams::new();
        assert!(p.check().is_ok());
        assert_eq!(p.clone().neighbors(0).check(), Err(EmbedParamsError::Neighbors));
        assert_eq!(p.clone().dims(0).check(), Err(EmbedParamsError::Dims));
        assert_eq!(p.clone().resample(1).check(), Err(EmbedParamsError::Resample(1)));
        assert_eq!(p.clone().c_atn(0.5).check(), Err(EmbedParamsError::Atn(0.5)));
        assert_eq!(p.c_ctn(f64::INFINITY).check(), Err(EmbedParamsError::Ctn(f64::INFINITY)));
    }
}
