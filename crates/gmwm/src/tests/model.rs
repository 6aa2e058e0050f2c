//! Models (docs/methods.md §0.2–§0.3): the text language, canonical display, rules, operators.

use gmwm::model::{
    ar, ar1, ar1_with, arma, arma11_with, arma_with, dr, dr_with, gm, gm_with, ma, ma1, qn, rw, wn,
    wn_with, Component, Model, ModelError, ModelParseError, ModelSpec, ParseErrorKind, ProcessKind,
};
use proptest::prelude::*;

fn parse(text: &str) -> Model {
    Model::parse(text).unwrap_or_else(|e| panic!("{e}\n{}", e.render()))
}

fn c(kind: ProcessKind, values: &[Option<f64>]) -> Component {
    Component::new(kind, values.to_vec()).unwrap()
}

/// Bitwise equality of two models (derived `==` treats -0 and 0 as equal).
fn assert_same_bits(a: &Model, b: &Model) {
    assert_eq!(a, b);
    let bits = |m: &Model| -> Vec<Option<u64>> {
        m.values().iter().map(|v| v.map(f64::to_bits)).collect()
    };
    assert_eq!(bits(a), bits(b), "{a} vs {b}");
}

#[test]
fn model_documented_forms_parse_to_expected_structure() {
    use ProcessKind::*;
    let n = None;
    let cases: Vec<(&str, Vec<Component>, &str)> = vec![
        (
            "3*GM()+WN()+QN()+RW()",
            vec![gm(), gm(), gm(), wn(), qn(), rw()],
            "3*GM()+WN()+QN()+RW()",
        ),
        (
            "AR1(phi=0.9, sigma2=0.1)+WN(sigma2=1)",
            vec![c(Ar1, &[Some(0.9), Some(0.1)]), c(Wn, &[Some(1.0)])],
            "AR1(phi=0.9, sigma2=0.1)+WN(sigma2=1)",
        ),
        ("ARMA(2,1)", vec![arma(2, 1)], "ARMA(2,1)"),
        ("AR(2)", vec![ar(2)], "AR(2)"),
        ("MA(3)", vec![ma(3)], "MA(3)"),
        (
            "2*AR1()+WN()+RW()+QN()+DR()",
            vec![ar1(), ar1(), wn(), rw(), qn(), dr()],
            "2*AR1()+WN()+RW()+QN()+DR()",
        ),
        (
            "GM(beta=0.25, sigma2_gm=7.08e-9)",
            vec![c(Gm, &[Some(0.25), Some(7.08e-9)])],
            "GM(beta=0.25, sigma2_gm=7.08e-9)",
        ),
        (
            "ARMA(1,1)(ar1=0.5, ma1=0.3, sigma2=1)",
            vec![c(Arma(1, 1), &[Some(0.5), Some(0.3), Some(1.0)])],
            "ARMA(1,1)(ar1=0.5, ma1=0.3, sigma2=1)",
        ),
        (
            "ARMA11(phi=0.5, theta=0.3, sigma2=1)",
            vec![c(Arma11, &[Some(0.5), Some(0.3), Some(1.0)])],
            "ARMA11(phi=0.5, theta=0.3, sigma2=1)",
        ),
        (
            "AR1(0.9, 0.1)",
            vec![c(Ar1, &[Some(0.9), Some(0.1)])],
            "AR1(phi=0.9, sigma2=0.1)",
        ),
        // case, spaces, bare names, partial values, negative and scientific numbers
        (
            "  3 * gm ( ) + Wn + qN()\t+ rw( )  ",
            vec![gm(), gm(), gm(), wn(), qn(), rw()],
            "3*GM()+WN()+QN()+RW()",
        ),
        (
            "AR1(phi = .9) + WN()",
            vec![c(Ar1, &[Some(0.9), n]), wn()],
            "AR1(phi=0.9)+WN()",
        ),
        (
            "ar1(SIGMA2=1E-3)",
            vec![c(Ar1, &[n, Some(1e-3)])],
            "AR1(sigma2=0.001)",
        ),
        (
            "DR(-2.5e-7)",
            vec![c(Dr, &[Some(-2.5e-7)])],
            "DR(omega=-2.5e-7)",
        ),
        (
            "AR(2)(0.5, -0.2, 1)",
            vec![c(Ar(2), &[Some(0.5), Some(-0.2), Some(1.0)])],
            "AR(2)(ar1=0.5, ar2=-0.2, sigma2=1)",
        ),
        (
            "ARMA(2, 1) (ma1=-1.5)",
            vec![c(Arma(2, 1), &[n, n, Some(-1.5), n])],
            "ARMA(2,1)(ma1=-1.5)",
        ),
        ("ARMA(0,2)", vec![arma(0, 2)], "ARMA(0,2)"),
        (
            "2*GM(beta=1, sigma2_gm=2)",
            vec![
                c(Gm, &[Some(1.0), Some(2.0)]),
                c(Gm, &[Some(1.0), Some(2.0)]),
            ],
            "GM(beta=1, sigma2_gm=2)+GM(beta=1, sigma2_gm=2)",
        ),
        (
            "WN(+3e6)+RW(gamma2=4.)",
            vec![c(Wn, &[Some(3e6)]), c(Rw, &[Some(4.0)])],
            "WN(sigma2=3e6)+RW(gamma2=4)",
        ),
        (
            "AR1(0.9, sigma2=2)",
            vec![c(Ar1, &[Some(0.9), Some(2.0)])],
            "AR1(phi=0.9, sigma2=2)",
        ),
        ("MA1()+QN()", vec![ma1(), qn()], "MA1()+QN()"),
    ];
    for (text, components, canonical) in cases {
        let m = parse(text);
        assert_eq!(m.components(), &components[..], "{text}");
        assert_eq!(m.to_string(), canonical, "{text}");
        assert_same_bits(&parse(canonical), &m);
        let serialized = serde_json::to_string(&m).unwrap();
        assert_eq!(serialized, format!("{canonical:?}"));
        let back: Model = serde_json::from_str(&serialized).unwrap();
        assert_eq!(back, m);
    }
}

#[test]
fn model_queries_follow_methods_0_2_and_0_3() {
    let m = parse("AR1(phi=0.9, sigma2=0.1)+WN()+ARMA(1,1)");
    assert_eq!(m.n_params(), 2 + 1 + 3);
    assert_eq!(
        m.param_names(),
        [
            (0, "phi"),
            (0, "sigma2"),
            (1, "sigma2"),
            (2, "ar1"),
            (2, "ma1"),
            (2, "sigma2")
        ]
        .map(|(i, s)| (i, s.to_string()))
    );
    assert_eq!(m.values(), [Some(0.9), Some(0.1), None, None, None, None]);
    // §13.20 deviation: the unspecified WN stays None instead of the placeholder 3
    assert!(!m.is_guess_mode() && !m.is_fully_specified());
    let full = m.with_values(&[0.5, 1.0, 2.0, -0.3, 0.7, 3.0]).unwrap();
    assert!(full.is_fully_specified());
    assert_eq!(
        full.to_string(),
        "AR1(phi=0.5, sigma2=1)+WN(sigma2=2)+ARMA(1,1)(ar1=-0.3, ma1=0.7, sigma2=3)"
    );
    assert_eq!(full.without_values(), m.without_values());
    assert!(m.without_values().is_guess_mode());
    assert!(matches!(
        m.with_values(&[0.5]),
        Err(ModelError::ThetaLength {
            expected: 6,
            found: 1
        })
    ));
    assert!(matches!(
        m.with_values(&[0.5, -1.0, 2.0, -0.3, 0.7, 3.0]),
        Err(ModelError::BadParameter { component: 0, ref name, .. }) if name == "sigma2"
    ));
    let g = parse("3*GM()+WN()");
    assert_eq!(g.count(ProcessKind::Gm), 3);
    assert!(g.count(ProcessKind::Gm) > 0 && g.count(ProcessKind::Ar1) == 0);
    assert_eq!(g.n_components(), 4);
    assert_eq!(ProcessKind::Arma(2, 1).name(), "ARMA(2,1)");
    assert_eq!(ProcessKind::Ma(2).param_names(), ["ma1", "ma2", "sigma2"]);
}

#[test]
fn model_operators_match_text() {
    let built = (3 * gm() + wn() + qn() + rw()).build().unwrap();
    assert_eq!(built, parse("3*GM()+WN()+QN()+RW()"));
    let built = (ar1_with(0.9, 0.1).unwrap() + wn_with(1.0).unwrap())
        .build()
        .unwrap();
    assert_eq!(built, parse("AR1(phi=0.9, sigma2=0.1)+WN(sigma2=1)"));
    let built = (gm_with(0.25, 7.08e-9).unwrap() + dr_with(-1.0).unwrap())
        .build()
        .unwrap();
    assert_eq!(built, parse("GM(0.25, 7.08e-9)+DR(-1)"));
    let built = (arma_with(&[0.5], &[0.3], 1.0).unwrap() + wn())
        .build()
        .unwrap();
    assert_eq!(built, parse("ARMA(1,1)(0.5, 0.3, 1)+WN()"));
    let built = ModelSpec::from(arma11_with(0.5, 0.3, 1.0).unwrap())
        .build()
        .unwrap();
    assert_eq!(built, parse("ARMA11(0.5, 0.3, 1)"));
    // Model + Component and Model + Model are unvalidated specs
    let m = parse("2*AR1()");
    assert_eq!(
        (m.clone() + wn() + parse("QN()")).build().unwrap(),
        parse("2*AR1()+WN()+QN()")
    );
    assert_eq!(
        Model::try_from(ar1().with("phi", 0.9).unwrap() + rw()).unwrap(),
        parse("AR1(phi=0.9)+RW()")
    );
    // operator errors surface at build()
    assert_eq!(
        (0 * gm() + wn()).build(),
        Err(ModelError::BadMultiplier { k: 0 })
    );
    assert!(matches!(
        (m + gm()).build(),
        Err(ModelError::GmAr1Mixed { gm: 1, ar1: 2 })
    ));
    assert!(matches!(
        (ar(0) + wn()).build(),
        Err(ModelError::BadOrder { order: 0, .. })
    ));
    assert!(matches!(
        ar1().with("beta", 1.0),
        Err(ModelError::UnknownParameter { ref valid, .. }) if valid == &["phi", "sigma2"]
    ));
    assert!(matches!(
        ar1().with("phi", 1.0),
        Err(ModelError::BadParameter { .. })
    ));
    assert!(wn_with(0.0).is_err() && wn_with(f64::NAN).is_err() && dr_with(f64::INFINITY).is_err());
}

#[test]
fn model_rule_violations_are_rejected() {
    use ModelError::*;
    let cases: Vec<(Vec<Component>, ModelError)> = vec![
        (vec![], Empty),
        (
            vec![wn(), rw(), wn()],
            Repeated {
                kind: "WN".into(),
                count: 2,
            },
        ),
        (
            vec![qn(), qn(), qn()],
            Repeated {
                kind: "QN".into(),
                count: 3,
            },
        ),
        (
            vec![dr(), dr()],
            Repeated {
                kind: "DR".into(),
                count: 2,
            },
        ),
        (
            vec![rw(), rw()],
            Repeated {
                kind: "RW".into(),
                count: 2,
            },
        ),
        (vec![gm(), wn(), ar1()], GmAr1Mixed { gm: 1, ar1: 1 }),
        (
            vec![ma1(), ar(2)],
            ArmaFamily {
                first: "MA1".into(),
                second: "AR(2)".into(),
            },
        ),
        (
            vec![arma(1, 1), arma(1, 1)],
            Repeated {
                kind: "ARMA(1,1)".into(),
                count: 2,
            },
        ),
        (
            vec![Component {
                kind: ProcessKind::Wn,
                values: vec![None, None],
            }],
            WrongLength {
                component: 0,
                kind: "WN".into(),
                expected: 1,
                found: 2,
            },
        ),
        (
            vec![
                wn(),
                Component {
                    kind: ProcessKind::Gm,
                    values: vec![Some(-1.0), None],
                },
            ],
            BadParameter {
                component: 1,
                kind: "GM".into(),
                name: "beta".into(),
                value: -1.0,
                expected: "a finite rate > 0",
            },
        ),
    ];
    for (components, expected) in cases {
        let text = format!("{components:?}");
        assert_eq!(Model::new(components), Err(expected), "{text}");
    }
    // the same rules through the parser, pointing at the offending term
    for (text, column) in [
        ("WN()+RW()+WN()", 11),
        ("2*WN()", 1),
        ("GM()+WN()+AR1()", 11),
        ("WN()+2*AR1()+GM()", 14),
        // a repeated vibration line does not hide which of GM and AR1 came second
        ("2*SIN()+GM()+WN()+AR1()", 19),
        ("MA1()+ARMA(1,1)", 7),
    ] {
        let e = Model::parse(text).unwrap_err();
        assert!(matches!(e.kind(), ParseErrorKind::Rule(_)), "{text}: {e}");
        assert_eq!(e.column(), column, "{text}: {e}\n{}", e.render());
    }
}

/// Vibration lines repeat (one `SIN()` per line, issue 28) like AR1/GM terms: `k*SIN()` parses,
/// prints back collapsed, and mixes with one repeating AR1 kind.
#[test]
fn vibration_lines_may_repeat() {
    for text in ["2*SIN()+WN()", "2*AR1()+WN()+RW()+2*SIN()"] {
        let m = Model::parse(text).unwrap();
        assert_eq!(m.to_string(), text);
        assert_eq!(m.count(ProcessKind::Sin), 2);
    }
    let m = Model::parse("SIN(amplitude=1, omega=0.1)+SIN(amplitude=2, omega=0.01)").unwrap();
    assert_eq!(m.count(ProcessKind::Sin), 2);
}

/// Coarse error classes for the bad-string table.
#[derive(Debug, PartialEq)]
enum Class {
    Empty,
    Syntax,
    UnknownProcess,
    UnknownParameter,
    Duplicate,
    TooMany,
    BadNumber,
    BadMultiplier,
    BadParameter,
    BadOrder,
    Repeated,
    Mixed,
}

fn class(e: &ModelParseError) -> Class {
    match e.kind() {
        ParseErrorKind::Empty => Class::Empty,
        ParseErrorKind::Syntax => Class::Syntax,
        ParseErrorKind::UnknownProcess { .. } => Class::UnknownProcess,
        ParseErrorKind::UnknownParameter { .. } => Class::UnknownParameter,
        ParseErrorKind::DuplicateParameter { .. } => Class::Duplicate,
        ParseErrorKind::TooManyValues { .. } => Class::TooMany,
        ParseErrorKind::BadNumber => Class::BadNumber,
        ParseErrorKind::BadMultiplier => Class::BadMultiplier,
        ParseErrorKind::Rule(ModelError::BadParameter { .. }) => Class::BadParameter,
        ParseErrorKind::Rule(ModelError::BadOrder { .. }) => Class::BadOrder,
        ParseErrorKind::Rule(ModelError::Repeated { .. }) => Class::Repeated,
        ParseErrorKind::Rule(ModelError::GmAr1Mixed { .. }) => Class::Mixed,
        other => panic!("unexpected kind {other:?}"),
    }
}

#[test]
fn model_bad_strings_report_kind_and_column() {
    use Class::*;
    // (input, class, 1-based column of the offending character)
    let table: &[(&str, Class, usize)] = &[
        ("", Empty, 1),
        ("   ", Empty, 4),
        ("AR1(phi=0.9,, sigma2=1)", Syntax, 13),
        ("GN()", UnknownProcess, 1),
        ("WN()+XYZ()", UnknownProcess, 6),
        ("AR1(ph=0.9)", UnknownParameter, 5),
        ("AR1(phi=0.9, phi=0.8)", Duplicate, 14),
        ("AR1(0.9, phi=0.8)", Duplicate, 10),
        ("AR1(0.9, 0.1, 3)", TooMany, 15),
        ("AR1(phi=0.9", Syntax, 12),
        ("WN() WN()", Syntax, 6),
        ("WN()+", Syntax, 6),
        ("+WN()", Syntax, 1),
        ("WN()+)", Syntax, 6),
        ("0*GM()", BadMultiplier, 1),
        ("2.5*GM()", BadMultiplier, 1),
        ("101*GM()", BadMultiplier, 1),
        ("3 GM()", Syntax, 3),
        ("WN(sigma2=-1)", BadParameter, 11),
        ("WN(0)", BadParameter, 4),
        ("AR1(phi=1.5)", BadParameter, 9),
        ("GM(beta=-0.1)", BadParameter, 9),
        ("WN(1e999)", BadNumber, 4),
        ("WN(1e)", BadNumber, 4),
        ("WN(1x)", BadNumber, 4),
        ("WN(-)", BadNumber, 4),
        ("WN(nan)", UnknownParameter, 4),
        ("WN(sigma2)", Syntax, 10),
        ("WN(sigma2=)", BadNumber, 11),
        ("WN(1,)", Syntax, 6),
        ("AR1(phi=0.5 0.1)", Syntax, 13),
        ("AR1(phi=0.5, 0.1)", Syntax, 14),
        ("AR(0)", BadOrder, 4),
        ("AR(101)", BadOrder, 4),
        ("AR()", Syntax, 4),
        ("AR", Syntax, 3),
        ("ARMA(2)", Syntax, 7),
        ("ARMA(0,0)", BadOrder, 1),
        ("ARMA(1,1,1)", Syntax, 9),
        ("AR(2.5)", Syntax, 4),
        ("WN()+WN()", Repeated, 6),
        ("2*GM()+AR1()", Mixed, 8),
        ("WN()é", Syntax, 5),
        ("é+WN()", Syntax, 1),
        ("WN(sigma2=1)(2)", Syntax, 13),
    ];
    assert!(table.len() >= 20);
    for (input, expected_class, column) in table {
        let e = Model::parse(input).unwrap_err();
        let shown = format!("{input:?}: {e}\n{}", e.render());
        assert_eq!(class(&e), *expected_class, "{shown}");
        assert_eq!(e.column(), *column, "{shown}");
        assert_eq!(e.input(), *input);
        assert!(
            e.offset() <= input.len() && input.is_char_boundary(e.offset()),
            "{shown}"
        );
        let msg = e.to_string();
        assert!(
            msg.starts_with(&format!("model {input:?}: at column {column}: expected ")),
            "{msg}"
        );
        assert!(msg.contains(", found "), "{msg}");
        // the caret sits under the column
        let caret_line = e.render().lines().nth(1).unwrap().to_string();
        assert_eq!(caret_line.chars().count(), *column, "{shown}");
    }
}

#[test]
fn model_error_messages_point_at_the_problem() {
    let e = Model::parse("AR1(phi=0.9,, sigma2=1)").unwrap_err();
    assert_eq!(
        e.to_string(),
        r#"model "AR1(phi=0.9,, sigma2=1)": at column 13: expected a parameter name, found ",""#
    );
    assert_eq!(e.render(), "AR1(phi=0.9,, sigma2=1)\n            ^");
    let e = Model::parse("3*GN()+WN()").unwrap_err();
    assert_eq!(
        *e.kind(),
        ParseErrorKind::UnknownProcess {
            name: "GN".into(),
            suggestion: Some("GM()".into())
        }
    );
    assert!(e.to_string().ends_with("; did you mean GM()?"), "{e}");
    for (typo, suggestion) in [
        ("AR2()", "AR(2)"),
        ("ARMA21", "ARMA(2,1)"),
        ("MA3", "MA(3)"),
        ("WM", "WN()"),
        ("ARMA12()", "ARMA(1,2)"),
        ("arm11", "ARMA11()"),
    ] {
        let e = Model::parse(typo).unwrap_err();
        assert!(
            e.to_string()
                .ends_with(&format!("did you mean {suggestion}?")),
            "{typo}: {e}"
        );
    }
    let e = Model::parse("GM(sigma2=1)").unwrap_err();
    assert_eq!(
        *e.kind(),
        ParseErrorKind::UnknownParameter {
            name: "sigma2".into(),
            valid: vec!["beta".into(), "sigma2_gm".into()]
        }
    );
    assert!(e.to_string().contains("beta, sigma2_gm"), "{e}");
    let e = Model::parse("2*GM()+WN(sigma2=-1)").unwrap_err();
    assert!(
        matches!(e.rule(), Some(ModelError::BadParameter { component: 2, value, .. }) if *value == -1.0),
        "{e}"
    );
    assert!(e.to_string().contains("variance > 0"), "{e}");
    assert!(e.to_string().contains(r#"found "-1""#), "{e}");
    let e = Model::parse("AR1(phi=0.9").unwrap_err();
    assert!(
        e.to_string()
            .ends_with(r#"expected "," or ")", found end of input"#),
        "{e}"
    );
}

/// One random valid component: kind, and per parameter maybe a value from its domain.
fn component_strategy(kind: ProcessKind) -> impl Strategy<Value = Component> {
    let n = kind.n_params();
    let value = move |i: usize| {
        let domain = kind.param_domain(i).unwrap();
        let any_finite = any::<f64>().prop_filter("finite", |v| v.is_finite());
        let magnitude = (-320i32..308, 1.0f64..10.0).prop_map(|(e, m)| m * 10f64.powi(e));
        let v: BoxedStrategy<f64> = match domain {
            gmwm::model::ParamDomain::Variance | gmwm::model::ParamDomain::Rate => prop_oneof![
                magnitude.prop_filter("positive", |v| *v > 0.0 && v.is_finite()),
                any_finite
                    .prop_map(f64::abs)
                    .prop_filter("positive", |v| *v > 0.0),
                Just(f64::MIN_POSITIVE / 1024.0),
                Just(f64::MAX),
            ]
            .boxed(),
            gmwm::model::ParamDomain::UnitInterval => prop_oneof![
                -0.999999f64..0.999999,
                (-320i32..-1, 1.0f64..10.0, any::<bool>()).prop_map(|(e, m, neg)| if neg {
                    -m
                } else {
                    m
                } * 10f64
                    .powi(e)),
                Just(-0.0),
            ]
            .boxed(),
            _ => prop_oneof![any_finite, Just(-0.0), magnitude].boxed(),
        };
        proptest::option::of(v)
    };
    (0..n)
        .map(value)
        .collect::<Vec<_>>()
        .prop_map(move |values| Component { kind, values })
}

fn model_strategy() -> impl Strategy<Value = Model> {
    let repeat_kind = prop_oneof![Just(ProcessKind::Gm), Just(ProcessKind::Ar1)];
    let arma_kind = proptest::option::of(prop_oneof![
        Just(ProcessKind::Ma1),
        Just(ProcessKind::Arma11),
        (1usize..4).prop_map(ProcessKind::Ar),
        (1usize..4).prop_map(ProcessKind::Ma),
        (0usize..3, 0usize..3)
            .prop_filter("p+q>=1", |(p, q)| p + q > 0)
            .prop_map(|(p, q)| ProcessKind::Arma(p, q)),
    ]);
    (
        repeat_kind,
        0usize..5,
        proptest::sample::subsequence(
            vec![
                ProcessKind::Wn,
                ProcessKind::Qn,
                ProcessKind::Rw,
                ProcessKind::Dr,
            ],
            0..=4,
        ),
        arma_kind,
        any::<bool>(),
    )
        .prop_flat_map(|(rk, k, singles, arma, guess_repeats)| {
            let mut kinds = vec![rk; k];
            kinds.extend(singles);
            kinds.extend(arma);
            if kinds.is_empty() {
                kinds.push(ProcessKind::Wn);
            }
            let comps: Vec<BoxedStrategy<Component>> = kinds
                .into_iter()
                .map(|kind| {
                    if guess_repeats && kind.may_repeat() {
                        Just(Component::guess(kind)).boxed()
                    } else {
                        component_strategy(kind).boxed()
                    }
                })
                .collect();
            comps.prop_shuffle()
        })
        .prop_map(|components| Model::new(components).unwrap())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn model_display_parse_round_trip(m in model_strategy()) {
        let text = m.to_string();
        let back = Model::parse(&text).map_err(|e| TestCaseError::fail(format!("{e}")))?;
        prop_assert_eq!(&back, &m, "{}", text);
        let bits = |m: &Model| -> Vec<Option<u64>> {
            m.values().iter().map(|v| v.map(f64::to_bits)).collect()
        };
        prop_assert_eq!(bits(&back), bits(&m));
        prop_assert_eq!(back.to_string(), text);
    }

    #[test]
    fn model_parse_never_panics_on_arbitrary_text(s in "\\PC{0,40}") {
        let _ = Model::parse(&s);
    }

    #[test]
    fn model_parse_never_panics_on_near_miss_text(
        s in "[ 0-9a-zA-Z_.,+*=()\\-é\t]{0,40}",
        m in model_strategy(),
        cut in any::<proptest::sample::Index>(),
        insert in "[ 0-9a-zA-Z_.,+*=()\\-é]{0,3}",
    ) {
        let _ = Model::parse(&s);
        // splice junk into a valid model's text at a char boundary
        let text = m.to_string();
        let bounds: Vec<usize> = text.char_indices().map(|(i, _)| i).chain([text.len()]).collect();
        let at = bounds[cut.index(bounds.len())];
        let mutated = format!("{}{}{}", &text[..at], insert, &text[at..]);
        match Model::parse(&mutated) {
            Ok(_) => {}
            Err(e) => {
                prop_assert!(e.offset() <= mutated.len() && mutated.is_char_boundary(e.offset()));
                prop_assert!(e.column() >= 1 && e.column() <= mutated.chars().count() + 1);
                let _ = e.render();
            }
        }
    }
}

#[test]
fn model_types_are_send_sync_clone() {
    fn check<T: Send + Sync + Clone>() {}
    check::<Model>();
    check::<ModelSpec>();
    check::<ModelParseError>();
    check::<ModelError>();
}
