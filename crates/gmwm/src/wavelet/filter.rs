//! Published orthonormal scaling filters and their quadrature-mirror wavelet filters
//! (docs/methods.md §1.1, §1.8).
//!
//! The coefficients are the published values (Daubechies 1992; Percival & Walden 2000, *Wavelet
//! Methods for Time Series Analysis*, ch. 4; Fejer–Korovkin: Nielsen 2001; minimum bandwidth:
//! Morris & Peravali 1999; Battle–Lemarie: truncated published values), embedded as constants
//! and copied digit for digit from `shared/spec/filters.json`.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

use crate::error::ParamError;

/// A published wavelet filter, selected by its lower-case name (docs/methods.md §1.8).
///
/// Serialised, displayed and parsed by [`WaveletFilter::name`] (`"haar"`, `"d4"`, …, `"mb24"`);
/// parsing ignores ASCII case.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum WaveletFilter {
    /// Haar, L = 2 (docs/methods.md §1.1); the default, and the only filter with implied-WV
    /// formulas (§4).
    #[default]
    Haar,
    /// Daubechies extremal phase, L = 4 (docs/methods.md §1.8).
    D4,
    /// Daubechies extremal phase, L = 6 (docs/methods.md §1.8).
    D6,
    /// Daubechies extremal phase, L = 8 (docs/methods.md §1.8).
    D8,
    /// Daubechies extremal phase, L = 16 (docs/methods.md §1.8).
    D16,
    /// Fejer–Korovkin, L = 4 (docs/methods.md §1.8).
    Fk4,
    /// Fejer–Korovkin, L = 8 (docs/methods.md §1.8).
    Fk8,
    /// Fejer–Korovkin, L = 14 (docs/methods.md §1.8).
    Fk14,
    /// Fejer–Korovkin, L = 22 (docs/methods.md §1.8).
    Fk22,
    /// Battle–Lemarie (truncated), L = 14 (docs/methods.md §1.8).
    Bl14,
    /// Battle–Lemarie (truncated), L = 20 (docs/methods.md §1.8).
    Bl20,
    /// Least asymmetric (symmlet), L = 8 (docs/methods.md §1.8).
    La8,
    /// Least asymmetric (symmlet), L = 16 (docs/methods.md §1.8).
    La16,
    /// Least asymmetric (symmlet), L = 20 (docs/methods.md §1.8).
    La20,
    /// Minimum bandwidth, L = 4 (docs/methods.md §1.8); published with 7 significant digits only.
    Mb4,
    /// Minimum bandwidth, L = 8 (docs/methods.md §1.8).
    Mb8,
    /// Minimum bandwidth, L = 16 (docs/methods.md §1.8).
    Mb16,
    /// Minimum bandwidth, L = 24 (docs/methods.md §1.8).
    Mb24,
}

impl WaveletFilter {
    /// Every filter, in the order of the docs/methods.md §1.8 table.
    pub const ALL: [WaveletFilter; 18] = [
        WaveletFilter::Haar,
        WaveletFilter::D4,
        WaveletFilter::D6,
        WaveletFilter::D8,
        WaveletFilter::D16,
        WaveletFilter::Fk4,
        WaveletFilter::Fk8,
        WaveletFilter::Fk14,
        WaveletFilter::Fk22,
        WaveletFilter::Bl14,
        WaveletFilter::Bl20,
        WaveletFilter::La8,
        WaveletFilter::La16,
        WaveletFilter::La20,
        WaveletFilter::Mb4,
        WaveletFilter::Mb8,
        WaveletFilter::Mb16,
        WaveletFilter::Mb24,
    ];

    /// Lower-case name as used by the package and on the command line (docs/methods.md §1.8).
    pub fn name(&self) -> &'static str {
        match self {
            WaveletFilter::Haar => "haar",
            WaveletFilter::D4 => "d4",
            WaveletFilter::D6 => "d6",
            WaveletFilter::D8 => "d8",
            WaveletFilter::D16 => "d16",
            WaveletFilter::Fk4 => "fk4",
            WaveletFilter::Fk8 => "fk8",
            WaveletFilter::Fk14 => "fk14",
            WaveletFilter::Fk22 => "fk22",
            WaveletFilter::Bl14 => "bl14",
            WaveletFilter::Bl20 => "bl20",
            WaveletFilter::La8 => "la8",
            WaveletFilter::La16 => "la16",
            WaveletFilter::La20 => "la20",
            WaveletFilter::Mb4 => "mb4",
            WaveletFilter::Mb8 => "mb8",
            WaveletFilter::Mb16 => "mb16",
            WaveletFilter::Mb24 => "mb24",
        }
    }

    /// Filter length `L` (docs/methods.md §1.8), the number of scaling coefficients.
    #[allow(clippy::len_without_is_empty)] // a filter is never empty
    pub fn len(&self) -> usize {
        self.scaling().len()
    }

    /// Published scaling (low-pass) filter `g_0 .. g_{L-1}` (docs/methods.md §1.1, §1.8).
    ///
    /// Unscaled (DWT) normalisation: `sum g = sqrt2`, `sum g^2 = 1`, up to
    /// [`orthonormality_tolerance`](Self::orthonormality_tolerance).
    pub(crate) fn scaling(&self) -> &'static [f64] {
        match self {
            WaveletFilter::Haar => &HAAR,
            WaveletFilter::D4 => &D4,
            WaveletFilter::D6 => &D6,
            WaveletFilter::D8 => &D8,
            WaveletFilter::D16 => &D16,
            WaveletFilter::Fk4 => &FK4,
            WaveletFilter::Fk8 => &FK8,
            WaveletFilter::Fk14 => &FK14,
            WaveletFilter::Fk22 => &FK22,
            WaveletFilter::Bl14 => &BL14,
            WaveletFilter::Bl20 => &BL20,
            WaveletFilter::La8 => &LA8,
            WaveletFilter::La16 => &LA16,
            WaveletFilter::La20 => &LA20,
            WaveletFilter::Mb4 => &MB4,
            WaveletFilter::Mb8 => &MB8,
            WaveletFilter::Mb16 => &MB16,
            WaveletFilter::Mb24 => &MB24,
        }
    }

    /// Wavelet (high-pass) filter by the quadrature mirror rule `h_l = (-1)^l g_{L-1-l}`
    /// (docs/methods.md §1.1).
    ///
    /// # Examples
    /// ```
    /// use gmwm::WaveletFilter;
    /// let h = WaveletFilter::Haar.wavelet();
    /// assert!((h[0] - 0.5f64.sqrt()).abs() < 1e-15 && (h[1] + 0.5f64.sqrt()).abs() < 1e-15);
    /// ```
    pub fn wavelet(&self) -> Vec<f64> {
        quadrature_mirror(self.scaling())
    }

    /// Precision the published table carries: the largest acceptable deviation in
    /// `sum g = sqrt2`, `sum g^2 = 1` and `sum_l g_l g_{l+2k} = 0` (docs/methods.md §1.8).
    ///
    /// Per family: worst deviation observed in the table, then the tolerance (about 2–3 times it).
    /// - `haar`, `d4`, `d6`, `fk4`: full double precision; worst `9e-16`, tolerance `1e-14`.
    /// - `d8`, `d16`, `la8`, `la16`, `fk14`: 13–16 published digits; worst `2.4e-12`, tolerance
    ///   `1e-11`.
    /// - `bl14`, `fk22`: worst `4.7e-11`, tolerance `1e-10`.
    /// - `la20`, `bl20`: some coefficients carry only 11–13 significant digits; worst `3.5e-10`,
    ///   tolerance `1e-9` (the `filters.json` note's "1e-10 or better" does not hold for these).
    /// - `fk8`: worst `1.6e-9`, tolerance `2e-9`.
    /// - `mb4`, `mb8`, `mb16`, `mb24`: 7 significant digits; worst `2.0e-7` (`sum g^2` of `mb4`),
    ///   tolerance `5e-7`.
    ///
    /// The wavelet filter's sum `sum h` (its gain at frequency 0) then vanishes only to about the
    /// square root of this tolerance: `fk22` has `sum h = 9.7e-6`, so its MODWT of a constant
    /// series is about `7e-6` times the constant, not zero.
    #[cfg(test)]
    pub(crate) fn orthonormality_tolerance(&self) -> f64 {
        match self {
            WaveletFilter::Haar | WaveletFilter::D4 | WaveletFilter::D6 | WaveletFilter::Fk4 => {
                1e-14
            }
            WaveletFilter::D8
            | WaveletFilter::D16
            | WaveletFilter::La8
            | WaveletFilter::La16
            | WaveletFilter::Fk14 => 1e-11,
            WaveletFilter::Bl14 | WaveletFilter::Fk22 => 1e-10,
            WaveletFilter::La20 | WaveletFilter::Bl20 => 1e-9,
            WaveletFilter::Fk8 => 2e-9,
            WaveletFilter::Mb4 | WaveletFilter::Mb8 | WaveletFilter::Mb16 | WaveletFilter::Mb24 => {
                5e-7
            }
        }
    }

    /// MODWT scaling filter `g~ = g / sqrt2` (docs/methods.md §1.1, §1.2).
    #[cfg(test)]
    pub(crate) fn modwt_scaling(&self) -> Vec<f64> {
        self.scaling()
            .iter()
            .map(|g| g * std::f64::consts::FRAC_1_SQRT_2)
            .collect()
    }

    /// MODWT wavelet filter `h~ = h / sqrt2` (docs/methods.md §1.1, §1.2).
    #[cfg(test)]
    pub(crate) fn modwt_wavelet(&self) -> Vec<f64> {
        self.wavelet()
            .iter()
            .map(|h| h * std::f64::consts::FRAC_1_SQRT_2)
            .collect()
    }

    /// Comma-separated list of every valid name, for error messages.
    fn valid_names() -> String {
        let names: Vec<&str> = Self::ALL.iter().map(WaveletFilter::name).collect();
        format!("one of {}", names.join(", "))
    }
}

/// Longest filter of [`WaveletFilter::ALL`] (`mb24`); sizes stack buffers of filter taps.
pub(crate) const MAX_FILTER_LEN: usize = 24;

/// Wavelet and scaling taps multiplied by `scale`, on the stack (no allocation per transform).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Taps {
    /// `scale * h_l`, zero beyond `len`.
    pub(crate) h: [f64; MAX_FILTER_LEN],
    /// `scale * g_l`, zero beyond `len`.
    pub(crate) g: [f64; MAX_FILTER_LEN],
    /// Filter length `L`.
    pub(crate) len: usize,
}

impl Taps {
    /// Taps of `filter` times `scale` (1 for the DWT, `1/sqrt2` for the MODWT, docs/methods.md
    /// §1.1).
    pub(crate) fn new(filter: WaveletFilter, scale: f64) -> Self {
        let g = filter.scaling();
        let mut taps = Taps {
            h: [0.0; MAX_FILTER_LEN],
            g: [0.0; MAX_FILTER_LEN],
            len: g.len(),
        };
        for (l, &c) in g.iter().enumerate() {
            taps.g[l] = scale * c;
            let mirror = scale * g[g.len() - 1 - l];
            taps.h[l] = if l % 2 == 0 { mirror } else { -mirror };
        }
        taps
    }

    /// Wavelet taps `h_0..h_{L-1}`.
    pub(crate) fn h(&self) -> &[f64] {
        &self.h[..self.len]
    }

    /// Scaling taps `g_0..g_{L-1}`.
    pub(crate) fn g(&self) -> &[f64] {
        &self.g[..self.len]
    }
}

/// Quadrature mirror of a scaling filter, `h_l = (-1)^l g_{L-1-l}` (docs/methods.md §1.1).
pub(crate) fn quadrature_mirror(g: &[f64]) -> Vec<f64> {
    g.iter()
        .rev()
        .enumerate()
        .map(|(l, &c)| if l % 2 == 0 { c } else { -c })
        .collect()
}

impl fmt::Display for WaveletFilter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.pad(self.name())
    }
}

impl FromStr for WaveletFilter {
    type Err = ParamError;

    /// Parses a filter name, ignoring ASCII case and surrounding whitespace (docs/methods.md §1.8).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let t = s.trim();
        Self::ALL
            .into_iter()
            .find(|f| f.name().eq_ignore_ascii_case(t))
            .ok_or_else(|| ParamError::new("filter", s, Self::valid_names()))
    }
}

/// Published scaling filter `haar` (L = 2), copied from `shared/spec/filters.json`.
#[allow(clippy::approx_constant)] // the published digits, 1 ulp below FRAC_1_SQRT_2
const HAAR: [f64; 2] = [0.7071067811865475, 0.7071067811865475];
/// Published scaling filter `d4` (L = 4), copied from `shared/spec/filters.json`.
const D4: [f64; 4] = [
    0.4829629131445341,
    0.8365163037378077,
    0.2241438680420134,
    -0.1294095225512603,
];
/// Published scaling filter `d6` (L = 6), copied from `shared/spec/filters.json`.
const D6: [f64; 6] = [
    0.3326705529500827,
    0.8068915093110928,
    0.4598775021184915,
    -0.1350110200102546,
    -0.0854412738820267,
    0.0352262918857096,
];
/// Published scaling filter `d8` (L = 8), copied from `shared/spec/filters.json`.
const D8: [f64; 8] = [
    0.2303778133074431,
    0.7148465705484058,
    0.6308807679358788,
    -0.0279837694166834,
    -0.1870348117179132,
    0.0308413818353661,
    0.0328830116666778,
    -0.0105974017850021,
];
/// Published scaling filter `d16` (L = 16), copied from `shared/spec/filters.json`.
const D16: [f64; 16] = [
    0.0544158422431049,
    0.3128715909143031,
    0.6756307362972904,
    0.5853546836541907,
    -0.0158291052563816,
    -0.2840155429615702,
    0.0004724845739124,
    0.1287474266204837,
    -0.0173693010018083,
    -0.0440882539307952,
    0.0139810279173995,
    0.0087460940474061,
    -0.0048703529934518,
    -0.000391740373377,
    0.0006754494064506,
    -0.0001174767841248,
];
/// Published scaling filter `fk4` (L = 4), copied from `shared/spec/filters.json`.
const FK4: [f64; 4] = [
    0.6539275555697651,
    0.7532724928394872,
    0.05317922877905981,
    -0.0461657148152177,
];
/// Published scaling filter `fk8` (L = 8), copied from `shared/spec/filters.json`.
const FK8: [f64; 8] = [
    0.3492381118637999,
    0.7826836203840648,
    0.4752651350794712,
    -0.09968332845057319,
    -0.1599780974340301,
    0.04310666810651625,
    0.04258163167758178,
    -0.01900017885373592,
];
/// Published scaling filter `fk14` (L = 14), copied from `shared/spec/filters.json`.
const FK14: [f64; 14] = [
    0.2603717692913964,
    0.6868914772395985,
    0.6115546539595115,
    0.05142165414211914,
    -0.2456139281621916,
    -0.04857533908585527,
    0.1242825609215128,
    0.02222673962246313,
    -0.06399737303914167,
    -0.00507437254997285,
    0.02977971159037902,
    -0.003297479152708717,
    -0.009270613374448239,
    0.003514100970435962,
];
/// Published scaling filter `fk22` (L = 22), copied from `shared/spec/filters.json`.
const FK22: [f64; 22] = [
    0.1938961077599566,
    0.5894521909294277,
    0.6700849629420265,
    0.21562984913477,
    -0.2280288557715772,
    -0.1644657152688429,
    0.11154914372207,
    0.1101552649340661,
    -0.0660845167937792,
    -0.07184168192312605,
    0.04354236762555708,
    0.04477521218440976,
    -0.02974288074927414,
    -0.02597087308902119,
    0.02028448606667798,
    0.01296424941108978,
    -0.01288599056244363,
    -0.004838432636440189,
    0.00717380316527169,
    0.0003612855622194901,
    -0.002676991638581043,
    0.000880577368638464,
];
/// Published scaling filter `bl14` (L = 14), copied from `shared/spec/filters.json`.
const BL14: [f64; 14] = [
    0.0120154192834842,
    0.0172133762994439,
    -0.0649080035533744,
    -0.064131289818917,
    0.3602184608985549,
    0.7819215932965554,
    0.4836109156937821,
    -0.0568044768822707,
    -0.1010109208664125,
    0.0447423494687405,
    0.0204642075778225,
    -0.0181266051311065,
    -0.0032832978473081,
    0.0022918339541009,
];
/// Published scaling filter `bl20` (L = 20), copied from `shared/spec/filters.json`.
const BL20: [f64; 20] = [
    0.0008625782242896,
    0.0007154205305517,
    -0.0070567640909701,
    0.0005956827305406,
    0.0496861265075979,
    0.0262403647054251,
    -0.1215521061578162,
    -0.0150192395413644,
    0.5137098728334054,
    0.7669548365010849,
    0.3402160135110789,
    -0.0878787107378667,
    -0.0670899071680668,
    0.0338423550064691,
    -0.0008687519578684,
    -0.0230054612862905,
    -0.0011404297773324,
    0.0050716491945793,
    0.0003401492622332,
    -0.0004101159165852,
];
/// Published scaling filter `la8` (L = 8), copied from `shared/spec/filters.json`.
const LA8: [f64; 8] = [
    -0.07576571478935668,
    -0.02963552764596039,
    0.4976186676325629,
    0.803738751805386,
    0.29785779560560505,
    -0.09921954357695636,
    -0.01260396726226383,
    0.03222310060407815,
];
/// Published scaling filter `la16` (L = 16), copied from `shared/spec/filters.json`.
const LA16: [f64; 16] = [
    -0.0033824159513594,
    -0.0005421323316355,
    0.0316950878103452,
    0.0076074873252848,
    -0.1432942383510542,
    -0.0612733590679088,
    0.4813596512592012,
    0.7771857516997478,
    0.3644418948359564,
    -0.0519458381078751,
    -0.0272190299168137,
    0.0491371796734768,
    0.0038087520140601,
    -0.0149522583367926,
    -0.0003029205145516,
    0.0018899503329007,
];
/// Published scaling filter `la20` (L = 20), copied from `shared/spec/filters.json`.
const LA20: [f64; 20] = [
    0.000770159809103,
    9.56326707837e-05,
    -0.0086412992759401,
    -0.0014653825833465,
    0.0459272392237649,
    0.0116098939129724,
    -0.1594942788575307,
    -0.0708805358108615,
    0.4716906668426588,
    0.7695100370143388,
    0.3838267612253823,
    -0.0355367403054689,
    -0.0319900568281631,
    0.049994972079156,
    0.0057649120455518,
    -0.020354939803946,
    -0.000804358934537,
    0.0045931735836703,
    5.7036084339e-05,
    -0.0004593294205481,
];
/// Published scaling filter `mb4` (L = 4), copied from `shared/spec/filters.json`.
const MB4: [f64; 4] = [0.4801755, 0.8372545, 0.2269312, -0.1301477];
/// Published scaling filter `mb8` (L = 8), copied from `shared/spec/filters.json`.
const MB8: [f64; 8] = [
    0.06436345,
    0.007106015,
    -0.1108673,
    0.2947855,
    0.7351331,
    0.5725771,
    0.01847751,
    -0.1673619,
];
/// Published scaling filter `mb16` (L = 16), copied from `shared/spec/filters.json`.
const MB16: [f64; 16] = [
    0.005765899,
    0.009620427,
    -0.04984698,
    -0.02483876,
    0.05474628,
    -0.01987986,
    -0.05656657,
    0.2345342,
    0.6701646,
    0.6349228,
    0.1188725,
    -0.2278359,
    -0.0577657,
    0.1136116,
    0.02173677,
    -0.0130277,
];
/// Published scaling filter `mb24` (L = 24), copied from `shared/spec/filters.json`.
const MB24: [f64; 24] = [
    5.361301e-05,
    0.001193006,
    -0.002062335,
    -0.01644859,
    0.01027154,
    0.1479342,
    -0.004575448,
    -0.3622424,
    -0.3091111,
    0.2556731,
    0.6176385,
    0.4581101,
    0.1949147,
    0.1243531,
    0.1689456,
    0.1019512,
    -0.006559513,
    -0.002658282,
    0.04199576,
    -0.001482995,
    -0.004879053,
    0.0007456041,
    0.0004745736,
    -2.132706e-05,
];

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::SQRT_2;

    /// docs/methods.md §1.8: `sum g = sqrt2`, `sum g^2 = 1`, `sum_l g_l g_{l+2k} = 0` (k >= 1),
    /// each to the precision of the published table.
    #[test]
    fn filter_scaling_is_orthonormal() {
        for f in WaveletFilter::ALL {
            let g = f.scaling();
            let tol = f.orthonormality_tolerance();
            assert_eq!(g.len(), f.len());
            assert!(f.len() % 2 == 0 && f.len() <= MAX_FILTER_LEN, "{f}");
            let sum: f64 = g.iter().sum();
            assert!((sum - SQRT_2).abs() <= tol, "{f}: sum g = {sum}");
            let energy: f64 = g.iter().map(|c| c * c).sum();
            assert!((energy - 1.0).abs() <= tol, "{f}: sum g^2 = {energy}");
            for k in 1..f.len() / 2 {
                let dot: f64 = (0..f.len() - 2 * k).map(|l| g[l] * g[l + 2 * k]).sum();
                assert!(dot.abs() <= tol, "{f}: shift {k}: {dot}");
            }
        }
    }

    /// The tolerance is tight: the 7-digit `mb4` fails the full-precision tolerance of `d4`.
    #[test]
    fn filter_tolerance_is_not_vacuous() {
        let g = WaveletFilter::Mb4.scaling();
        let energy: f64 = g.iter().map(|c| c * c).sum();
        assert!((energy - 1.0).abs() > WaveletFilter::D4.orthonormality_tolerance());
    }

    /// docs/methods.md §1.1: `h_l = (-1)^l g_{L-1-l}`; `h` sums to 0, has unit energy and is
    /// orthogonal to every even shift of `g`.
    #[test]
    fn filter_wavelet_is_quadrature_mirror() {
        for f in WaveletFilter::ALL {
            let (g, h) = (f.scaling(), f.wavelet());
            let len = f.len();
            for l in 0..len {
                let sign = if l % 2 == 0 { 1.0 } else { -1.0 };
                assert_eq!(h[l], sign * g[len - 1 - l], "{f} l = {l}");
            }
            let tol = f.orthonormality_tolerance();
            // sum h = +-G(1/2) vanishes only to about sqrt(tol): |G(0)|^2 + |G(1/2)|^2 =
            // 2 (sum g^2 + 2 sum_k sum_l g_l g_{l+2k}) gives (sum h)^2 <= (2L + 6) tol
            let sum_h: f64 = h.iter().sum();
            assert!(
                sum_h * sum_h <= (2 * len + 6) as f64 * tol,
                "{f}: sum h = {sum_h}"
            );
            for k in 0..len / 2 {
                let dot: f64 = (0..len - 2 * k).map(|l| g[l] * h[l + 2 * k]).sum();
                assert!(dot.abs() <= tol, "{f}: shift {k}: {dot}");
            }
            let taps = Taps::new(f, 0.5);
            assert!(taps.h().iter().zip(&h).all(|(a, b)| *a == 0.5 * b), "{f}");
            assert!(taps.g().iter().zip(g).all(|(a, b)| *a == 0.5 * b), "{f}");
        }
        let h = WaveletFilter::D4.wavelet();
        let g = WaveletFilter::D4.scaling();
        assert_eq!(h, vec![g[3], -g[2], g[1], -g[0]]);
    }

    /// docs/methods.md §1.1: MODWT filters are the DWT filters over sqrt2.
    #[test]
    fn filter_modwt_filters_are_rescaled() {
        assert_eq!(WaveletFilter::Haar.modwt_scaling().len(), 2);
        for (a, b) in WaveletFilter::Haar.modwt_wavelet().iter().zip([0.5, -0.5]) {
            assert!((a - b).abs() < 1e-16);
        }
    }

    #[test]
    fn filter_names_round_trip() {
        assert_eq!(WaveletFilter::ALL.len(), 18);
        for f in WaveletFilter::ALL {
            assert_eq!(f.to_string(), f.name());
            assert_eq!(f.name().parse::<WaveletFilter>(), Ok(f));
            assert_eq!(f.name().to_uppercase().parse::<WaveletFilter>(), Ok(f));
            let json = serde_json::to_string(&f).unwrap();
            assert_eq!(json, format!("\"{}\"", f.name()));
            assert_eq!(serde_json::from_str::<WaveletFilter>(&json).unwrap(), f);
        }
        assert_eq!(WaveletFilter::default(), WaveletFilter::Haar);
        assert_eq!(format!("{:>5}", WaveletFilter::D4), "   d4");
    }

    #[test]
    fn filter_bad_names_rejected() {
        for bad in ["", "fk6", "w4", "d5", "haar2", "la 8"] {
            let e = bad.parse::<WaveletFilter>().unwrap_err();
            assert_eq!(e.name, "filter");
            assert_eq!(e.value, bad);
            assert!(e.expected.contains("haar, d4, d6") && e.expected.contains("mb24"));
        }
    }
}
