//! The effective random walk (docs/methods.md §20): K when the recording cannot tell a slow
//! Gauss–Markov term from the random walk.
//!
//! A Gauss–Markov (AR1) term whose correlation time is long against the scales where the
//! random walk shows looks like a random walk over every scale the recording observes, and at
//! a length where the planner (§18) cannot determine that correlation time, the selection
//! drops the term or keeps it by chance: the random walk then absorbs it in one replicate and
//! not in the next, and an interval on "the RW term's K" covers the truth a third of the time
//! (issue 29, reproduced by `tests::coverage`). What the recording determines is the random
//! walk of the whole slow part: the K of the identified model with those terms taken out and a
//! random walk in their place, fitted on the same WV. That is what a white-noise + random-walk
//! filter needs, and whichever model the selection picks, it estimates the same number.
//!
//! A term counts when the planner's 95% half-width of its correlation time at this length is
//! undetermined (beyond ±100%) and the time is longer than the cluster time of the Allan
//! deviation's minimum (faster terms, a sensor's filter, are white to a navigation filter).

use super::pipeline::Estimate;
use super::plan::Plan;
use crate::fit::report::significant;
use crate::model::Model;
use crate::process::LatentProcess;

/// The slow terms the planner leaves undetermined (process indices) and their correlation
/// times, s.
pub(crate) fn unresolved_slow_terms(plan: &Plan, slower_than_s: f64) -> Vec<(usize, f64)> {
    plan.quantities
        .iter()
        .filter_map(|q| {
            let process = q.process?;
            let undetermined = q
                .half_width
                .first()
                .copied()
                .flatten()
                .map_or(true, |w| w > 1.0);
            (undetermined && q.value > slower_than_s).then_some((process, q.value))
        })
        .collect()
}

/// `model` (every value set) in guess mode without the processes `dropped`, with a random
/// walk when it has none.
pub(crate) fn with_random_walk_for(
    model: &Model,
    dropped: &[usize],
    freq_hz: f64,
) -> Option<Model> {
    let processes = model.processes(freq_hz).ok()?;
    let mut parts: Vec<String> = processes
        .iter()
        .enumerate()
        .filter(|(i, _)| !dropped.contains(i))
        .map(|(_, p)| format!("{}()", p.name()))
        .collect();
    if !parts.iter().any(|p| p == "RW()") {
        parts.push("RW()".to_string());
    }
    parts.join("+").parse().ok()
}

/// The line a calibration's notes carry when its K is the effective random walk, and the
/// estimate's source.
pub(super) fn effective_random_walk_note(
    terms: &[(usize, f64)],
    model: &Model,
    own: Option<&Estimate>,
    effective: &Estimate,
    length_s: f64,
) -> (String, String) {
    let times: Vec<String> = terms
        .iter()
        .map(|(_, t)| format!("{} s", significant(*t, 3)))
        .collect();
    let own = own.map_or_else(
        || "the identified model has no random-walk term".to_string(),
        |e| {
            format!(
                "the identified model's own RW term gives K = {}",
                significant(e.value, 4)
            )
        },
    );
    let note = format!(
            "K is the effective random walk over the {} s recorded: a Gauss-Markov term of correlation time {} cannot be told from a random walk at this length (the planner leaves its time undetermined), so K counts it, fitted as {} (K = {}); {own}; docs/methods.md §20",
            significant(length_s, 3),
            times.join(", "),
            model.without_values(),
            significant(effective.value, 4),
        );
    let source = format!(
            "effective random walk over the scales recorded ({} fitted; counts the Gauss-Markov term of {})",
            model.without_values(),
            times.join(", ")
        );
    (note, source)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_slow_term_is_replaced_by_a_random_walk_once() {
        let m: Model = "GM(beta=0.005, sigma2_gm=4e-8)+WN(sigma2=6e-6)+RW(gamma2=2e-12)"
            .parse()
            .unwrap();
        let e = with_random_walk_for(&m, &[0], 200.0).unwrap();
        assert_eq!(e.without_values().to_string(), "WN()+RW()");
        let no_rw: Model = "AR1(phi=0.999, sigma2=1e-9)+WN(sigma2=6e-6)"
            .parse()
            .unwrap();
        let e = with_random_walk_for(&no_rw, &[0], 200.0).unwrap();
        assert_eq!(e.without_values().to_string(), "WN()+RW()");
    }

    #[test]
    fn the_planner_decides_which_terms_are_unresolved() {
        // a 200 s Gauss–Markov term beside a random walk: undetermined at 2.9 h (the planner
        // gives K ±86% there), determined at 12 days
        let m: Model = "GM(beta=0.005, sigma2_gm=4e-8)+WN(sigma2=6e-6)+RW(gamma2=2e-12)"
            .parse()
            .unwrap();
        let short = Plan::new(&m, 200.0, &[10_440.0], 0.05, &[]).unwrap();
        let terms = unresolved_slow_terms(&short, 0.0);
        assert_eq!(terms.len(), 1);
        assert_eq!(terms[0].0, 0);
        assert!((terms[0].1 - 200.0).abs() < 1e-6);
        // a term faster than the threshold is not the random walk's
        assert!(unresolved_slow_terms(&short, 500.0).is_empty());
        let long = Plan::new(&m, 200.0, &[1.0e6], 0.05, &[]).unwrap();
        assert!(unresolved_slow_terms(&long, 0.0).is_empty());
    }
}
