//! Shared test data: a rich, valid description using every feature of the types.
#![allow(dead_code)]

use model_description::*;

pub fn real(
    name: &str,
    vr: u32,
    causality: Causality,
    variability: Variability,
    initial: Option<Initial>,
    start: Option<f64>,
    unit: Option<&str>,
) -> ScalarVariable {
    ScalarVariable {
        name: name.to_string(),
        value_reference: vr,
        description: None,
        causality,
        variability,
        initial,
        variable_type: VariableType::Real {
            start,
            unit: unit.map(str::to_string),
            derivative: None,
            min: None,
            max: None,
            nominal: None,
        },
    }
}

pub fn with_derivative(mut v: ScalarVariable, of: u32) -> ScalarVariable {
    if let VariableType::Real { derivative, .. } = &mut v.variable_type {
        *derivative = Some(of);
    }
    v
}

pub fn unknown(index: u32, deps: Option<Vec<u32>>, kinds: Option<Vec<DependencyKind>>) -> Unknown {
    Unknown { index, dependencies: deps, dependencies_kind: kinds }
}

/// 16 variables of all four types; see the comments for their 1-based indices.
pub fn rich() -> ModelDescription {
    use Causality as C;
    use DependencyKind as K;
    use Initial as I;
    use Variability as V;
    let mut vars = vec![
        // 1
        real("time", 0, C::Independent, V::Continuous, None, None, Some("s")),
        // 2: state, output
        real("x", 1, C::Output, V::Continuous, Some(I::Exact), Some(0.5), Some("m")),
        // 3
        with_derivative(real("der(x)", 2, C::Local, V::Continuous, Some(I::Calculated), None, Some("m/s")), 2),
        // 4: state
        real("v", 3, C::Local, V::Continuous, Some(I::Approx), Some(0.0), Some("m/s")),
        // 5
        with_derivative(real("der(v)", 4, C::Local, V::Continuous, None, None, Some("m/s2")), 4),
        // 6
        real("u", 5, C::Input, V::Continuous, None, Some(0.0), Some("N")),
        // 7
        real("mass", 6, C::Parameter, V::Fixed, None, Some(1200.0), Some("kg")),
        // 8
        real("k", 7, C::Parameter, V::Tunable, Some(I::Exact), Some(1e-3), None),
        // 9
        real("w", 8, C::CalculatedParameter, V::Fixed, None, None, Some("kg")),
    ];
    if let VariableType::Real { min, max, nominal, .. } = &mut vars[1].variable_type {
        *min = Some(f64::NEG_INFINITY);
        *max = Some(f64::INFINITY);
        *nominal = Some(1.5);
    }
    if let VariableType::Real { min, max, .. } = &mut vars[5].variable_type {
        *min = Some(-10.0);
        *max = Some(10.0);
    }
    vars[1].description = Some("position \"x\" <of> the body & more".into());
    vars[6].description = Some("multi\nline\tdescription, ünïcödé ✓".into());
    vars.push(ScalarVariable {
        // 10
        name: "gear".into(),
        value_reference: 0,
        description: None,
        causality: C::Input,
        variability: V::Discrete,
        initial: None,
        variable_type: VariableType::Integer { start: Some(1), min: Some(-1), max: Some(6) },
    });
    vars.push(ScalarVariable {
        // 11
        name: "count".into(),
        value_reference: 1,
        description: None,
        causality: C::Output,
        variability: V::Discrete,
        initial: Some(I::Calculated),
        variable_type: VariableType::Integer { start: None, min: Some(i32::MIN), max: Some(i32::MAX) },
    });
    vars.push(ScalarVariable {
        // 12
        name: "on".into(),
        value_reference: 0,
        description: None,
        causality: C::Input,
        variability: V::Discrete,
        initial: None,
        variable_type: VariableType::Boolean { start: Some(true) },
    });
    vars.push(ScalarVariable {
        // 13
        name: "flag".into(),
        value_reference: 1,
        description: None,
        causality: C::Output,
        variability: V::Discrete,
        initial: Some(I::Calculated),
        variable_type: VariableType::Boolean { start: None },
    });
    vars.push(ScalarVariable {
        // 14
        name: "label".into(),
        value_reference: 0,
        description: Some(String::new()),
        causality: C::Parameter,
        variability: V::Fixed,
        initial: None,
        variable_type: VariableType::String { start: Some("a \"quoted\" <label> & 'x'\n\ttab  two spaces".into()) },
    });
    // 15
    vars.push(real("c", 9, C::Local, V::Constant, None, Some(std::f64::consts::PI), None));
    // 16
    vars.push(real("temp", 10, C::Output, V::Continuous, Some(I::Calculated), None, Some("degC")));

    let units = vec![
        Unit::si("s", 0, 0, 1, 0),
        Unit::si("m", 0, 1, 0, 0),
        Unit::si("m/s", 0, 1, -1, 0),
        Unit::si("m/s2", 0, 1, -2, 0),
        Unit::si("N", 1, 1, -2, 0),
        Unit::si("kg", 1, 0, 0, 0),
        Unit { name: "degC".into(), base_unit: Some(BaseUnit { k: 1, offset: 273.15, ..BaseUnit::default() }) },
        Unit {
            name: "km/h".into(),
            base_unit: Some(BaseUnit { m: 1, s: -1, factor: 1.0 / 3.6, ..BaseUnit::default() }),
        },
        Unit {
            name: "odd".into(),
            base_unit: Some(BaseUnit {
                kg: -3,
                m: 2,
                s: 1,
                a: -1,
                k: 4,
                mol: -2,
                cd: 7,
                rad: -5,
                factor: 1e-300,
                offset: -1e300,
            }),
        },
        Unit { name: "1".into(), base_unit: None },
    ];

    let structure = ModelStructure {
        outputs: vec![
            unknown(2, Some(vec![]), None),
            unknown(11, None, None),
            unknown(13, Some(vec![12]), Some(vec![K::Dependent])),
            unknown(16, Some(vec![2, 4, 6]), Some(vec![K::Dependent, K::Constant, K::Fixed])),
        ],
        derivatives: vec![
            unknown(3, Some(vec![4]), Some(vec![K::Constant])),
            unknown(5, Some(vec![1, 2, 4, 6]), Some(vec![K::Tunable, K::Discrete, K::Dependent, K::Constant])),
        ],
        initial_unknowns: vec![
            unknown(3, Some(vec![4]), None),
            unknown(4, Some(vec![]), None),
            unknown(5, Some(vec![2, 4, 6, 7, 8]), None),
            unknown(9, Some(vec![7]), Some(vec![K::Constant])),
            unknown(11, None, None),
            unknown(13, Some(vec![12]), None),
            unknown(16, Some(vec![1, 2, 6]), None),
        ],
    };

    ModelDescription {
        fmi_version: "2.0".into(),
        model_name: "Rich & <odd> \"model\"".into(),
        guid: "{00000000-0000-0000-0000-000000000000}".into(),
        description: Some("A description with every feature".into()),
        author: Some("nigel-fmi".into()),
        version: Some("0.1.0".into()),
        copyright: Some("(c) nobody".into()),
        license: Some("MIT OR Apache-2.0".into()),
        generation_tool: Some("model-description tests".into()),
        generation_date_and_time: Some("2024-01-02T03:04:05Z".into()),
        variable_naming_convention: Some("structured".into()),
        number_of_event_indicators: 2,
        model_exchange: Some(ModelExchange {
            model_identifier: "rich_model".into(),
            completed_integrator_step_not_needed: true,
            can_get_and_set_fmu_state: true,
            can_serialize_fmu_state: true,
            provides_directional_derivative: true,
            ..Default::default()
        }),
        co_simulation: Some(CoSimulation {
            model_identifier: "rich_model".into(),
            can_handle_variable_communication_step_size: true,
            max_output_derivative_order: 1,
            can_get_and_set_fmu_state: true,
            can_serialize_fmu_state: true,
            ..Default::default()
        }),
        unit_definitions: units,
        type_definitions: vec![],
        log_categories: vec![
            LogCategory { name: "logEvents".into(), description: Some("Log events".into()) },
            LogCategory { name: "logStatusError".into(), description: None },
        ],
        default_experiment: Some(DefaultExperiment {
            start_time: Some(0.0),
            stop_time: Some(10.0),
            tolerance: Some(1e-6),
            step_size: Some(0.001),
        }),
        model_variables: vars,
        model_structure: structure,
    }
}

/// The smallest valid description: one CS interface, one parameter, nothing else.
pub fn minimal() -> ModelDescription {
    ModelDescription {
        fmi_version: "2.0".into(),
        model_name: "m".into(),
        guid: "{g}".into(),
        co_simulation: Some(CoSimulation { model_identifier: "m".into(), ..Default::default() }),
        model_variables: vec![real("p", 0, Causality::Parameter, Variability::Fixed, None, Some(1.0), None)],
        ..Default::default()
    }
}

pub fn fixture(name: &str) -> String {
    let path = format!("{}/tests/fixtures/{name}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// A tiny deterministic PRNG (xorshift64*).
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n.max(1) as u64) as usize
    }
}

/// The Python of the fmpy cross-checks: `$FMPY_PYTHON`, default `python3`.
pub fn python() -> String {
    std::env::var("FMPY_PYTHON").unwrap_or_else(|_| "python3".to_string())
}

/// Whether [`python`] can import fmpy. When it cannot: a failure if `$FMPY_PYTHON` is set
/// (the README's test command sets it to its venv), else a skip, said on stderr.
pub fn fmpy_available() -> bool {
    let available =
        std::process::Command::new(python()).args(["-c", "import fmpy"]).output().is_ok_and(|o| o.status.success());
    if !available {
        assert!(std::env::var_os("FMPY_PYTHON").is_none(), "FMPY_PYTHON={} cannot import fmpy", python());
        eprintln!("fmpy not importable with {}: cross-check skipped (set FMPY_PYTHON to require it)", python());
    }
    available
}

/// A scratch folder `<temp>/<prefix>-<pid>` for the fmpy cross-checks, `None` (skip) when
/// fmpy is not available ([`fmpy_available`]).
pub fn fmpy_scratch(prefix: &str) -> Option<std::path::PathBuf> {
    fmpy_available().then(|| std::env::temp_dir().join(format!("{prefix}-{}", std::process::id())))
}

/// The start of the fmpy scripts of [`fmpy_output`]: a `PROBLEM` line per finding of fmpy's
/// `validate_fmu` on the folder `sys.argv[1]`, then `md`, fmpy's reading of its
/// `modelDescription.xml`.
pub const FMPY_PRELUDE: &str = r#"
import sys
from fmpy import read_model_description
from fmpy.validation import validate_fmu
d = sys.argv[1]
for p in validate_fmu(d):
    print("PROBLEM", p.replace("\n", " "))
md = read_model_description(d, validate=False)
"#;

/// Writes `xml` to `dir/modelDescription.xml` and runs [`FMPY_PRELUDE`] and then `script`
/// on `dir`; their standard output, once asserted that they ran and that fmpy found no
/// problem. `name` labels the failures.
pub fn fmpy_output(name: &str, dir: &std::path::Path, xml: &str, script: &str) -> String {
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(dir.join("modelDescription.xml"), xml).unwrap();
    let script = format!("{FMPY_PRELUDE}{script}");
    let out = std::process::Command::new(python()).args(["-c", &script]).arg(dir).output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(out.status.success(), "{name}: {}\n{stdout}", String::from_utf8_lossy(&out.stderr));
    let problems: Vec<&str> = stdout.lines().filter(|l| l.starts_with("PROBLEM")).collect();
    assert!(problems.is_empty(), "{name}: fmpy problems:\n{}", problems.join("\n"));
    stdout
}
