//! The consensus axis: how a datum's residual scores a model.

/// Scores one datum's squared residual; a model's score is the sum over the data.
pub trait Consensus {
    /// Squared inlier threshold: residuals above it are outliers and score 0.
    fn threshold_sq(&self) -> f64;

    /// Contribution of one datum with squared residual `residual_sq` and weight `weight`.
    fn score(&self, residual_sq: f64, weight: f64) -> f64;
}

/// Classic RANSAC: each inlier scores 1, whatever its weight and residual.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InlierCount {
    threshold_sq: f64,
}

impl InlierCount {
    /// Inliers are residuals at most `threshold_px`.
    pub fn new(threshold_px: f64) -> Self {
        Self {
            threshold_sq: threshold_px * threshold_px,
        }
    }
}

impl Consensus for InlierCount {
    fn threshold_sq(&self) -> f64 {
        self.threshold_sq
    }

    #[inline]
    fn score(&self, residual_sq: f64, _weight: f64) -> f64 {
        if residual_sq <= self.threshold_sq {
            1.0
        } else {
            0.0
        }
    }
}

/// MSAC (Torr & Zisserman 2000) as a reward: an inlier scores `weight * (1 - r²/t²)`, so
/// tight fits and confident matches count more and the score varies smoothly with the model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Msac {
    threshold_sq: f64,
}

impl Msac {
    /// Inliers are residuals at most `threshold_px`.
    pub fn new(threshold_px: f64) -> Self {
        Self {
            threshold_sq: threshold_px * threshold_px,
        }
    }
}

impl Consensus for Msac {
    fn threshold_sq(&self) -> f64 {
        self.threshold_sq
    }

    #[inline]
    fn score(&self, residual_sq: f64, weight: f64) -> f64 {
        if residual_sq <= self.threshold_sq {
            weight * (1.0 - residual_sq / self.threshold_sq)
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scores() {
        let c = InlierCount::new(3.0);
        assert_eq!(c.score(9.0, 0.2), 1.0);
        assert_eq!(c.score(9.0001, 0.2), 0.0);
        let m = Msac::new(3.0);
        assert_eq!(m.score(0.0, 0.5), 0.5);
        assert!((m.score(4.5, 0.5) - 0.25).abs() < 1e-15);
        assert_eq!(m.score(10.0, 1.0), 0.0);
    }
}
