//! Candidate models of a selection: the nested sub-models of a full model (docs/methods.md §8.4)
//! and the common denominator of a user's list (§8.5).
//!
//! A candidate is a term list (`["AR1", "AR1", "WN"]`); the package keeps candidates in a
//! lexicographically ordered set of such lists (byte order of the names: "AR1" < "DR" < "GM" <
//! "QN" < "RW" < "WN"), which fixes their processing order; [`nested_candidates`] returns them
//! in that order. Values written in the models are dropped: every candidate is fitted in guess
//! mode (§8.6).

use super::SelectionError;
use crate::model::{Component, Model, ProcessKind};
use crate::process::{spec, Occurs, KINDS};
use std::collections::BTreeSet;

/// Largest number of terms of a full model for [`nested_candidates`]: `2^20 - 1` subsets are
/// enumerated (well under a second); a real full model has fewer than ten terms.
pub(crate) const MAX_NESTED_TERMS: usize = 20;

/// The term list of a model, space-joined as the package names its rows (`"AR1 AR1 WN"`).
#[cfg(test)]
pub(crate) fn terms(model: &Model) -> String {
    model
        .kinds()
        .iter()
        .map(ProcessKind::name)
        .collect::<Vec<_>>()
        .join(" ")
}

/// docs/methods.md §8.5: refuses ARMA-family terms (the package's check is inert, §13.17) and
/// repeated WN/QN/RW/DR (a validated [`Model`] cannot hold them; checked again for clarity).
pub(crate) fn check_candidate(model: &Model) -> Result<(), SelectionError> {
    let candidate = model.without_values().to_string();
    if let Some(kind) = model.kinds().into_iter().find(|k| k.is_arma_family()) {
        return Err(SelectionError::ArmaNotSupported { candidate, kind });
    }
    for kind in once_kinds() {
        if model.count(kind) > 1 {
            return Err(SelectionError::Repeated { candidate, kind });
        }
    }
    if mixed_pair(std::slice::from_ref(model)).is_some() {
        return Err(SelectionError::GmAr1Mixed {
            gm: candidate.clone(),
            ar1: candidate,
        });
    }
    Ok(())
}

/// The kinds that appear at most once in a model (WN, QN, RW, DR), in table order.
fn once_kinds() -> impl Iterator<Item = ProcessKind> {
    KINDS
        .iter()
        .copied()
        .filter(|&k| spec(k).occurs == Occurs::Once)
}

/// A candidate using a kind and one using the kind it reparametrises (GM, AR1), if any.
fn mixed_pair(models: &[Model]) -> Option<(&Model, &Model)> {
    KINDS.iter().find_map(|&kind| {
        let base = spec(kind).reparametrises?;
        let a = models.iter().find(|m| m.count(kind) > 0)?;
        let b = models.iter().find(|m| m.count(base) > 0)?;
        Some((a, b))
    })
}

fn model_of(kinds: &[ProcessKind]) -> Model {
    Model::new(kinds.iter().map(|&k| Component::guess(k)).collect())
        .expect("a non-empty subset of a valid model's terms is a valid model")
}

/// docs/methods.md §8.4: every non-empty subset of the full model's terms, terms kept in their
/// original order, identical term lists merged (which of several AR1s is dropped does not matter),
/// in the package's set order (byte order of the term lists), guess mode.
///
/// For `3*AR1()+WN()+RW()+QN()+DR()`: 63 candidates, from `AR1()` to `WN()+RW()+QN()+DR()`.
///
/// Cost: `2^terms` subsets.
///
/// # Errors
/// [`SelectionError::ArmaNotSupported`] (and the other refusals of §8.5);
/// [`SelectionError::TooManyTerms`] above [`MAX_NESTED_TERMS`] terms.
pub(crate) fn nested_candidates(full: &Model) -> Result<Vec<Model>, SelectionError> {
    check_candidate(full)?;
    let kinds = full.kinds();
    let n = kinds.len();
    if n > MAX_NESTED_TERMS {
        return Err(SelectionError::TooManyTerms {
            terms: n,
            max: MAX_NESTED_TERMS,
        });
    }
    let mut set: BTreeSet<Vec<String>> = BTreeSet::new();
    let mut lists: std::collections::HashMap<Vec<String>, Vec<ProcessKind>> =
        std::collections::HashMap::new();
    for mask in 1u32..(1u32 << n) {
        let chosen: Vec<ProcessKind> = (0..n)
            .filter(|&i| mask & (1 << i) != 0)
            .map(|i| kinds[i])
            .collect();
        let names: Vec<String> = chosen.iter().map(ProcessKind::name).collect();
        if set.insert(names.clone()) {
            lists.insert(names, chosen);
        }
    }
    Ok(set.iter().map(|names| model_of(&lists[names])).collect())
}

/// docs/methods.md §8.5: the common denominator of a list of candidates: as many AR1 (or GM) terms
/// as the candidate with most of them, likewise SIN, then WN, QN, RW, DR when any candidate has
/// them, in that order; guess mode. E.g. {AR1 WN}, {AR1 AR1 RW}, {QN DR} give `2*AR1()+WN()+QN()+RW()+DR()`.
///
/// # Errors
/// [`SelectionError::NoCandidates`] for an empty list; the refusals of §8.5 naming the
/// candidate: [`SelectionError::ArmaNotSupported`], [`SelectionError::Repeated`],
/// [`SelectionError::GmAr1Mixed`] (GM in one candidate, AR1 in another).
pub(crate) fn common_denominator(models: &[Model]) -> Result<Model, SelectionError> {
    if models.is_empty() {
        return Err(SelectionError::NoCandidates);
    }
    for m in models {
        check_candidate(m)?;
    }
    if let Some((gm, ar1)) = mixed_pair(models) {
        return Err(SelectionError::GmAr1Mixed {
            gm: gm.without_values().to_string(),
            ar1: ar1.without_values().to_string(),
        });
    }
    // each repeating kind as often as the candidate with most of it, then the kinds that
    // appear once when any candidate has them, in table order
    let mut kinds = Vec::new();
    for kind in KINDS.iter().copied().filter(|&k| k.may_repeat()) {
        let k = models.iter().map(|m| m.count(kind)).max().unwrap_or(0);
        kinds.extend(std::iter::repeat(kind).take(k));
    }
    for kind in once_kinds() {
        if models.iter().any(|m| m.count(kind) > 0) {
            kinds.push(kind);
        }
    }
    Ok(model_of(&kinds))
}

/// Whether two models have the same terms with the same multiplicities (order ignored): the
/// package's test for "a given model already is the common denominator".
pub(crate) fn same_terms(a: &Model, b: &Model) -> bool {
    let mut x = a.kinds();
    let mut y = b.kinds();
    x.sort();
    y.sort();
    x == y
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m(t: &str) -> Model {
        Model::parse(t).unwrap()
    }

    #[test]
    fn terms_join_names() {
        assert_eq!(terms(&m("2*AR1()+WN()")), "AR1 AR1 WN");
        assert_eq!(terms(&m("GM(beta=1, sigma2_gm=2)")), "GM");
    }

    #[test]
    fn nested_keeps_original_order_and_merges_duplicates() {
        let c = nested_candidates(&m("AR1()+WN()+AR1()")).unwrap();
        let t: Vec<String> = c.iter().map(terms).collect();
        // "AR1 WN" (first AR1 + WN) and "WN AR1" (WN + second AR1) are different lists
        assert_eq!(
            t,
            ["AR1", "AR1 AR1", "AR1 WN", "AR1 WN AR1", "WN", "WN AR1"]
        );
    }

    #[test]
    fn refusals_name_the_candidate() {
        let e = nested_candidates(&m("AR1()+MA1()")).unwrap_err();
        assert!(
            matches!(
                e,
                SelectionError::ArmaNotSupported {
                    kind: ProcessKind::Ma1,
                    ..
                }
            ),
            "{e}"
        );
        assert!(e.to_string().contains("AR1()+MA1()"), "{e}");
        let e = common_denominator(&[m("GM()+WN()"), m("AR1()")]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "candidate GM()+WN() uses GM but candidate AR1() uses AR1; all candidates must use \
             the same one (docs/methods.md §8.5)"
        );
        assert!(matches!(
            common_denominator(&[]),
            Err(SelectionError::NoCandidates)
        ));
        let many = Model::parse(&format!("{}*AR1()", MAX_NESTED_TERMS + 1)).unwrap();
        assert!(matches!(
            nested_candidates(&many),
            Err(SelectionError::TooManyTerms { .. })
        ));
    }

    #[test]
    fn same_terms_ignores_order() {
        assert!(same_terms(
            &m("WN()+AR1()"),
            &m("AR1(phi=0.5, sigma2=1)+WN()")
        ));
        assert!(!same_terms(&m("WN()+AR1()"), &m("2*AR1()+WN()")));
    }
}
