//! Every validation rule: a valid description reports nothing, each violation is reported.

mod common;

use common::*;
use model_description::*;

fn problems_of(md: &ModelDescription) -> Vec<Problem> {
    md.validate()
}

/// Asserts that `md` has a problem under `rule` (about `var`, if given) and returns it.
#[track_caller]
fn expect(md: &ModelDescription, rule: Rule, var: Option<&str>) -> Problem {
    let ps = problems_of(md);
    match ps.iter().find(|p| p.rule == rule && (var.is_none() || p.variable.as_deref() == var)) {
        Some(p) => {
            // Display names the rule and, when there is one, the variable.
            let s = p.to_string();
            assert!(s.contains(rule.as_str()), "{s}");
            if let Some(v) = var {
                assert!(s.contains(&format!("\"{v}\"")), "{s}");
            }
            p.clone()
        }
        None => panic!("expected {rule} for {var:?}, got {ps:#?}"),
    }
}

fn var_mut<'a>(md: &'a mut ModelDescription, name: &str) -> &'a mut ScalarVariable {
    md.model_variables.iter_mut().find(|v| v.name == name).unwrap()
}

/// `rich()` with the variable `name` of `variability`.
fn rich_with_variability(name: &str, variability: Variability) -> ModelDescription {
    let mut md = rich();
    var_mut(&mut md, name).variability = variability;
    md
}

fn set_start(v: &mut ScalarVariable, value: Option<f64>) {
    match &mut v.variable_type {
        VariableType::Real { start, .. } => *start = value,
        _ => panic!("not Real"),
    }
}

#[test]
fn valid_descriptions_report_nothing() {
    assert_eq!(problems_of(&rich()), vec![]);
    assert_eq!(problems_of(&minimal()), vec![]);
    assert_eq!(problems_of(&rich().with_content_guid()), vec![]);
}

#[test]
fn expected_model_structure_matches_rich() {
    let md = rich();
    let want = md.expected_model_structure();
    let idx = |l: &[Unknown]| l.iter().map(|u| u.index).collect::<Vec<_>>();
    assert_eq!(idx(&want.outputs), idx(&md.model_structure.outputs));
    assert_eq!(idx(&want.derivatives), idx(&md.model_structure.derivatives));
    assert_eq!(idx(&want.initial_unknowns), idx(&md.model_structure.initial_unknowns));
    assert_eq!(md.states(), vec![2, 4]);
    assert_eq!(md.state_derivatives(), vec![3, 5]);
    // A description whose structure is exactly the expected one validates.
    let mut m2 = md.clone();
    m2.model_structure = want;
    assert_eq!(problems_of(&m2), vec![]);
}

#[test]
fn fmi_version() {
    let mut md = minimal();
    md.fmi_version = "3.0".into();
    expect(&md, Rule::FmiVersion, None);
}

#[test]
fn needs_an_interface() {
    let mut md = rich();
    md.model_exchange = None;
    assert_eq!(problems_of(&md), vec![]);
    md.co_simulation = None;
    expect(&md, Rule::NoInterface, None);
}

#[test]
fn model_identifier_is_a_c_identifier() {
    for bad in ["", "1abc", "a-b", "a b", "ä", "a.b"] {
        let mut md = rich();
        md.co_simulation.as_mut().unwrap().model_identifier = bad.into();
        let p = expect(&md, Rule::ModelIdentifier, None);
        assert!(p.message.contains("CoSimulation"), "{p}");
        let mut md = rich();
        md.model_exchange.as_mut().unwrap().model_identifier = bad.into();
        expect(&md, Rule::ModelIdentifier, None);
    }
    for good in ["a", "_", "A_B_c9", "nigel_plant"] {
        assert!(is_c_identifier(good), "{good}");
    }
}

#[test]
fn unique_names() {
    let mut md = rich();
    var_mut(&mut md, "k").name = "mass".into();
    let p = expect(&md, Rule::DuplicateName, Some("mass"));
    assert!(p.message.contains("7") && p.message.contains("8"), "{p}");
    let mut md = rich();
    var_mut(&mut md, "k").name = String::new();
    expect(&md, Rule::EmptyName, None);
}

#[test]
fn unique_value_references_per_base_type() {
    // rich() reuses 0 and 1 across Real, Integer, Boolean and String: fine.
    assert_eq!(problems_of(&rich()), vec![]);
    let mut md = rich();
    var_mut(&mut md, "k").value_reference = 6; // = mass
    let p = expect(&md, Rule::DuplicateValueReference, Some("k"));
    assert!(p.message.contains("\"mass\"") && p.message.contains("Real"), "{p}");
    let mut md = rich();
    var_mut(&mut md, "flag").value_reference = 0; // = on (Boolean)
    expect(&md, Rule::DuplicateValueReference, Some("flag"));
}

#[test]
fn unique_unit_names() {
    let mut md = rich();
    md.unit_definitions.push(Unit::si("m", 0, 1, 0, 0));
    expect(&md, Rule::DuplicateUnit, None);
}

// The table of FMI 2.0 section 2.2.7, written out independently of the crate:
// rows variability, columns causality (parameter, calculatedParameter, input, output,
// local, independent). "-": illegal; A: exact only; B: calculated (default) or approx;
// C: calculated (default), exact or approx; D/E: legal, initial not allowed.
const TABLE: [[&str; 6]; 5] = [
    /* constant   */ ["-", "-", "-", "A", "A", "-"],
    /* fixed      */ ["A", "B", "-", "-", "B", "-"],
    /* tunable    */ ["A", "B", "-", "-", "B", "-"],
    /* discrete   */ ["-", "-", "D", "C", "C", "-"],
    /* continuous */ ["-", "-", "D", "C", "C", "E"],
];

#[test]
fn causality_variability_initial_table() {
    for (vi, variability) in Variability::ALL.into_iter().enumerate() {
        for (ci, causality) in Causality::ALL.into_iter().enumerate() {
            let cell = TABLE[vi][ci];
            let allowed: &[Initial] = match cell {
                "A" => &[Initial::Exact],
                "B" => &[Initial::Calculated, Initial::Approx],
                "C" => &[Initial::Calculated, Initial::Exact, Initial::Approx],
                _ => &[],
            };
            assert_eq!(legal_combination(causality, variability), cell != "-", "{causality:?} {variability:?}");
            assert_eq!(Initial::allowed(causality, variability), allowed, "{causality:?} {variability:?}");
            for initial in [None, Some(Initial::Exact), Some(Initial::Approx), Some(Initial::Calculated)] {
                let mut md = minimal();
                let eff = initial.or(allowed.first().copied());
                let needs_start =
                    causality == Causality::Input || matches!(eff, Some(Initial::Exact | Initial::Approx));
                let forbids_start = causality == Causality::Independent || eff == Some(Initial::Calculated);
                let start = (needs_start && !forbids_start).then_some(1.0);
                md.model_variables = vec![real("x", 0, causality, variability, initial, start, None)];
                md.model_structure = md.expected_model_structure();
                let ps = problems_of(&md);
                let table_rules: Vec<Rule> = ps
                    .iter()
                    .map(|p| p.rule)
                    .filter(|r| matches!(r, Rule::CausalityVariability | Rule::Initial))
                    .collect();
                let mut want = Vec::new();
                if cell == "-" {
                    want.push(Rule::CausalityVariability);
                }
                if let Some(i) = initial {
                    let input_like = matches!(causality, Causality::Input | Causality::Independent);
                    if input_like || (cell != "-" && !allowed.contains(&i)) {
                        want.push(Rule::Initial);
                    }
                }
                assert_eq!(table_rules, want, "{causality:?} {variability:?} {initial:?}: {ps:#?}");
                if cell != "-" && want.is_empty() {
                    assert_eq!(ps, vec![], "{causality:?} {variability:?} {initial:?}");
                }
            }
        }
    }
}

#[test]
fn illegal_combinations_are_named() {
    let p = expect(&rich_with_variability("mass", Variability::Continuous), Rule::CausalityVariability, Some("mass"));
    assert!(p.message.contains("parameter") && p.message.contains("continuous"), "{p}");
    for (name, variability) in [("u", Variability::Fixed), ("time", Variability::Discrete)] {
        expect(&rich_with_variability(name, variability), Rule::CausalityVariability, Some(name));
    }
}

#[test]
fn initial_rules() {
    let mut md = rich();
    var_mut(&mut md, "u").initial = Some(Initial::Exact);
    expect(&md, Rule::Initial, Some("u"));
    let mut md = rich();
    var_mut(&mut md, "time").initial = Some(Initial::Calculated);
    expect(&md, Rule::Initial, Some("time"));
    let mut md = rich();
    var_mut(&mut md, "mass").initial = Some(Initial::Approx);
    let p = expect(&md, Rule::Initial, Some("mass"));
    assert!(p.message.contains("allowed: exact"), "{p}");
    let mut md = rich();
    var_mut(&mut md, "w").initial = Some(Initial::Exact);
    set_start(var_mut(&mut md, "w"), Some(1.0));
    expect(&md, Rule::Initial, Some("w"));
    let mut md = rich();
    var_mut(&mut md, "c").initial = Some(Initial::Calculated);
    set_start(var_mut(&mut md, "c"), None);
    expect(&md, Rule::Initial, Some("c"));
}

#[test]
fn start_required() {
    for (name, initial) in [
        ("u", None),                  // input
        ("mass", None),               // parameter (default exact)
        ("k", Some(Initial::Exact)),  // exact
        ("v", Some(Initial::Approx)), // approx
        ("c", None),                  // constant (default exact)
        ("x", Some(Initial::Exact)),  // output exact
    ] {
        let mut md = rich();
        let v = var_mut(&mut md, name);
        v.initial = initial;
        set_start(v, None);
        let p = expect(&md, Rule::StartRequired, Some(name));
        assert!(p.message.contains("start"), "{p}");
    }
    let mut md = rich();
    if let VariableType::Integer { start, .. } = &mut var_mut(&mut md, "gear").variable_type {
        *start = None;
    }
    expect(&md, Rule::StartRequired, Some("gear"));
    let mut md = rich();
    var_mut(&mut md, "on").variable_type = VariableType::Boolean { start: None };
    expect(&md, Rule::StartRequired, Some("on"));
    let mut md = rich();
    var_mut(&mut md, "label").variable_type = VariableType::String { start: None };
    expect(&md, Rule::StartRequired, Some("label"));
}

#[test]
fn start_forbidden() {
    for name in ["der(x)", "der(v)", "w", "temp", "time"] {
        let mut md = rich();
        set_start(var_mut(&mut md, name), Some(1.0));
        expect(&md, Rule::StartForbidden, Some(name));
    }
    let mut md = rich();
    var_mut(&mut md, "flag").variable_type = VariableType::Boolean { start: Some(false) };
    expect(&md, Rule::StartForbidden, Some("flag"));
}

#[test]
fn independent_variable() {
    let mut md = rich();
    var_mut(&mut md, "time").variable_type = VariableType::Integer { start: None, min: None, max: None };
    expect(&md, Rule::Independent, Some("time"));
    expect(&md, Rule::ContinuousNonReal, Some("time"));
    let mut md = rich();
    md.model_variables.push(real("time2", 99, Causality::Independent, Variability::Continuous, None, None, None));
    let p = expect(&md, Rule::Independent, Some("time2"));
    assert!(p.message.contains("\"time\""), "{p}");
}

#[test]
fn only_real_is_continuous() {
    for name in ["gear", "on"] {
        expect(&rich_with_variability(name, Variability::Continuous), Rule::ContinuousNonReal, Some(name));
    }
}

#[test]
fn units_must_be_declared() {
    let mut md = rich();
    md.unit_definitions.retain(|u| u.name != "N");
    let p = expect(&md, Rule::UndeclaredUnit, Some("u"));
    assert!(p.message.contains("\"N\""), "{p}");
}

#[test]
fn derivative_must_point_at_a_real_continuous_variable() {
    let n = rich().model_variables.len() as u32;
    for (target, why) in
        [(0, "in 1..="), (n + 1, "in 1..="), (3, "itself"), (7, "not a Real continuous"), (10, "not a Real continuous")]
    {
        let mut md = rich();
        if let VariableType::Real { derivative, .. } = &mut var_mut(&mut md, "der(x)").variable_type {
            *derivative = Some(target);
        }
        let p = expect(&md, Rule::Derivative, Some("der(x)"));
        assert!(p.message.contains(why), "{target}: {p}");
    }
}

#[test]
fn bounds() {
    let set = |f: &dyn Fn(&mut ModelDescription)| {
        let mut md = rich();
        f(&mut md);
        md
    };
    let md = set(&|md| {
        if let VariableType::Real { min, max, .. } = &mut var_mut(md, "u").variable_type {
            *min = Some(2.0);
            *max = Some(1.0);
        }
    });
    expect(&md, Rule::Bounds, Some("u"));
    let md = set(&|md| set_start(var_mut(md, "u"), Some(-11.0)));
    let p = expect(&md, Rule::Bounds, Some("u"));
    assert!(p.message.contains("< min"), "{p}");
    let md = set(&|md| set_start(var_mut(md, "u"), Some(11.0)));
    let p = expect(&md, Rule::Bounds, Some("u"));
    assert!(p.message.contains("> max"), "{p}");
    let md = set(&|md| {
        var_mut(md, "gear").variable_type = VariableType::Integer { start: Some(7), min: Some(-1), max: Some(6) }
    });
    expect(&md, Rule::Bounds, Some("gear"));
    let md = set(&|md| {
        var_mut(md, "gear").variable_type = VariableType::Integer { start: Some(0), min: Some(1), max: Some(0) }
    });
    expect(&md, Rule::Bounds, Some("gear"));
    // Infinite bounds are fine (x has min=-INF, max=INF).
    assert_eq!(problems_of(&rich()), vec![]);
}

#[test]
fn nominal_is_positive() {
    for bad in [0.0, -1.0, f64::NAN] {
        let mut md = rich();
        if let VariableType::Real { nominal, .. } = &mut var_mut(&mut md, "x").variable_type {
            *nominal = Some(bad);
        }
        expect(&md, Rule::Nominal, Some("x"));
    }
}

/// The problem of `rule` (no variable named) in `rich()` after `change`.
fn expect_after(rule: Rule, change: impl FnOnce(&mut ModelDescription)) -> Problem {
    let mut md = rich();
    change(&mut md);
    expect(&md, rule, None)
}

fn indices(list: &[Unknown]) -> Vec<u32> {
    list.iter().map(|u| u.index).collect()
}

#[test]
fn outputs_exactly_in_order() {
    let p = expect_after(Rule::Outputs, |md| {
        md.model_structure.outputs.remove(1);
    });
    assert!(p.message.contains("\"count\""), "{p}");
    expect_after(Rule::Outputs, |md| md.model_structure.outputs.swap(0, 1));
    expect_after(Rule::Outputs, |md| md.model_structure.outputs.push(unknown(4, None, None)));
    // a new output not listed
    expect_after(Rule::Outputs, |md| var_mut(md, "v").causality = Causality::Output);
}

#[test]
fn derivatives_exactly() {
    expect_after(Rule::Derivatives, |md| {
        md.model_structure.derivatives.pop();
    });
    expect_after(Rule::Derivatives, |md| md.model_structure.derivatives.push(unknown(4, None, None)));
    expect_after(Rule::Derivatives, |md| md.model_structure.derivatives.push(unknown(3, None, None)));
    // Any order is fine.
    let mut md = rich();
    md.model_structure.derivatives.reverse();
    assert_eq!(problems_of(&md), vec![]);
}

#[test]
fn initial_unknowns_exactly_sorted() {
    let mut md = rich();
    assert_eq!(indices(&md.model_structure.initial_unknowns), vec![3, 4, 5, 9, 11, 13, 16]);
    md.model_structure.initial_unknowns.retain(|u| u.index != 9); // calculated parameter
    let p = expect(&md, Rule::InitialUnknowns, None);
    assert!(p.message.contains("\"w\""), "{p}");
    // state with approx
    expect_after(Rule::InitialUnknowns, |md| md.model_structure.initial_unknowns.retain(|u| u.index != 4));
    // output calculated
    expect_after(Rule::InitialUnknowns, |md| md.model_structure.initial_unknowns.retain(|u| u.index != 16));
    // output exact: not an unknown
    expect_after(Rule::InitialUnknowns, |md| md.model_structure.initial_unknowns.insert(0, unknown(2, None, None)));
    expect_after(Rule::InitialUnknowns, |md| md.model_structure.initial_unknowns.swap(0, 1));
    expect_after(Rule::InitialUnknowns, |md| md.model_structure.initial_unknowns.push(unknown(16, None, None)));
}

#[test]
fn indices_in_range() {
    let n = rich().model_variables.len() as u32;
    for bad in [0, n + 1] {
        let mut md = rich();
        md.model_structure.outputs.push(unknown(bad, None, None));
        let p = expect(&md, Rule::IndexOutOfRange, None);
        assert!(p.message.contains(&format!("1..={n}")), "{p}");
        let mut md = rich();
        md.model_structure.initial_unknowns[0].dependencies = Some(vec![bad]);
        expect(&md, Rule::IndexOutOfRange, Some("der(x)"));
    }
}

#[test]
fn dependencies_ascending() {
    let mut md = rich();
    md.model_structure.outputs[3].dependencies = Some(vec![4, 2, 6]);
    expect(&md, Rule::DependencyOrder, Some("temp"));
    let mut md = rich();
    md.model_structure.outputs[3].dependencies = Some(vec![2, 2, 6]);
    expect(&md, Rule::DependencyOrder, Some("temp"));
}

#[test]
fn dependencies_only_on_knowns() {
    // Output on a parameter: not a known at run time.
    let mut md = rich();
    md.model_structure.outputs[3].dependencies = Some(vec![2, 4, 7]);
    let p = expect(&md, Rule::DependencyNotKnown, Some("temp"));
    assert!(p.message.contains("\"mass\""), "{p}");
    // Derivative on a local that is not a state.
    let mut md = rich();
    md.model_structure.derivatives[0].dependencies = Some(vec![3]);
    md.model_structure.derivatives[0].dependencies_kind = None;
    expect(&md, Rule::DependencyNotKnown, Some("der(x)"));
    // Initial unknown on a calculated variable: not a known in initialization.
    let mut md = rich();
    md.model_structure.initial_unknowns[6].dependencies = Some(vec![3]);
    expect(&md, Rule::DependencyNotKnown, Some("temp"));
    // ... but parameters and exact variables are.
    let mut md = rich();
    md.model_structure.initial_unknowns[6].dependencies = Some(vec![1, 2, 6, 7, 8, 15]);
    assert_eq!(problems_of(&md), vec![]);
}

#[test]
fn dependencies_kind_matches() {
    let mut md = rich();
    md.model_structure.outputs[3].dependencies_kind = Some(vec![DependencyKind::Dependent]);
    let p = expect(&md, Rule::DependenciesKind, Some("temp"));
    assert!(p.message.contains("3 dependencies but 1"), "{p}");
    let mut md = rich();
    md.model_structure.outputs[1].dependencies_kind = Some(vec![]);
    expect(&md, Rule::DependenciesKind, Some("count"));
}

#[test]
fn problems_display_rule_and_variable() {
    let mut md = rich();
    set_start(var_mut(&mut md, "u"), None);
    let ps = problems_of(&md);
    assert_eq!(ps.len(), 1, "{ps:#?}");
    assert_eq!(ps[0].to_string(), "[start-required] variable \"u\": inputs need a start value");
}
