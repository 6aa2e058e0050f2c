//! Compensated summation.

/// Neumaier's compensated sum (improved Kahan–Babuška): error independent of the number of terms
/// to first order, which keeps long accumulations (10^9 squared coefficients) accurate.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct NeumaierSum {
    sum: f64,
    compensation: f64,
}

impl NeumaierSum {
    /// Adds one term.
    #[inline]
    pub(crate) fn add(&mut self, v: f64) {
        let t = self.sum + v;
        if self.sum.abs() >= v.abs() {
            self.compensation += (self.sum - t) + v;
        } else {
            self.compensation += (v - t) + self.sum;
        }
        self.sum = t;
    }

    /// Compensated sum of all `values`.
    pub(crate) fn of(values: impl IntoIterator<Item = f64>) -> f64 {
        let mut s = Self::default();
        values.into_iter().for_each(|v| s.add(v));
        s.total()
    }

    /// The compensated total.
    #[inline]
    pub(crate) fn total(&self) -> f64 {
        self.sum + self.compensation
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neumaier_sum_recovers_cancelled_terms() {
        let mut s = NeumaierSum::default();
        for v in [1.0, 1e100, 1.0, -1e100] {
            s.add(v);
        }
        assert_eq!(s.total(), 2.0);
    }
}
