//! SSP 1.0 as other tools write it: parameter mappings (.ssm and inline) with their
//! transformations, units of .ssv values, values of system connectors (a system parameter
//! feeding FMU parameters, a value bound to a system input), the priority of bindings,
//! connections written sink first, `startElement=""`, unmatched names ignored with a
//! note, the DefaultExperiment's start time, the root system named in messages. Every
//! expected value is derived by hand next to its assertion; the C FMUs are
//! tests/cfmu/models.c (source: y = slope t; gain: y = k u).

mod common;
use common::{build_fmu, build_fmu_with, pack_ssp, work_dir, work_dir_with_source_and_gain, Model};
use nigel_cosim::{read_ssp, simulate, Algorithm, Experiment, ImportOptions};
use std::path::Path;

const HEAD: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon" xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription" xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" xmlns:ssm="http://ssp-standard.org/SSP1/SystemStructureParameterMapping" version="1.0" name="t">"#;

fn write(dir: &Path, name: &str, text: &str) {
    std::fs::write(dir.join(name), text).unwrap();
}

/// The value of `column` in the last row of a run of `ssd` to `stop` with step `h`
/// (ordered: each connection carried within the step).
fn last(ssd: &Path, column: &str, stop: f64, h: f64) -> f64 {
    let s = read_ssp(ssd, &ImportOptions::default()).unwrap();
    let mut e = Experiment::new(stop, h);
    e.algorithm = Algorithm::Ordered;
    e.record = Some(vec![column.to_string()]);
    let (r, _) = simulate(&s.system, &e).unwrap();
    // a one-instance system's columns are named by the variable alone
    let col = r.column(column).or_else(|| r.column(column.split_once('.').unwrap().1)).unwrap();
    *col.last().unwrap()
}

#[test]
fn parameter_mappings_with_transformations_and_units_of_values() {
    let dir = work_dir_with_source_and_gain("ssp-mapping");
    // the set: a slope in mm/s (its Units say mm/s = 0.001 m/s) and a gain; "unused" is
    // mapped nowhere, so it applies nowhere
    write(
        &dir,
        "values.ssv",
        r#"<ssv:ParameterSet xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon" version="1.0" name="v">
  <ssv:Parameters>
    <ssv:Parameter name="speed"><ssv:Real value="2500" unit="mm/s"/></ssv:Parameter>
    <ssv:Parameter name="gain"><ssv:Real value="2"/></ssv:Parameter>
    <ssv:Parameter name="unused"><ssv:Real value="99"/></ssv:Parameter>
  </ssv:Parameters>
  <ssv:Units><ssc:Unit name="mm/s"><ssc:BaseUnit m="1" s="-1" factor="0.001"/></ssc:Unit></ssv:Units>
</ssv:ParameterSet>"#,
    );
    // speed -> src.slope (unit converted, then x 2 + 1); gain -> amp.k (x 3 + 0.5)
    write(
        &dir,
        "map.ssm",
        r#"<ssm:ParameterMapping xmlns:ssm="http://ssp-standard.org/SSP1/SystemStructureParameterMapping" xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon" version="1.0">
  <ssm:MappingEntry source="speed" target="src.slope"><ssc:LinearTransformation factor="2" offset="1"/></ssm:MappingEntry>
  <ssm:MappingEntry source="gain" target="amp.k"><ssc:LinearTransformation factor="3" offset="0.5"/></ssm:MappingEntry>
  <ssm:MappingEntry source="" target="amp.u"/>
</ssm:ParameterMapping>"#,
    );
    let ssd = format!(
        r#"{HEAD}<ssd:System name="root">
  <ssd:ParameterBindings><ssd:ParameterBinding source="values.ssv"><ssd:ParameterMapping source="map.ssm"/></ssd:ParameterBinding></ssd:ParameterBindings>
  <ssd:Elements>
    <ssd:Component name="src" source="source.fmu"/>
    <ssd:Component name="amp" source="gain.fmu"/>
  </ssd:Elements>
  <ssd:Connections><ssd:Connection startElement="src" startConnector="y" endElement="amp" endConnector="u"/></ssd:Connections>
</ssd:System></ssd:SystemStructureDescription>"#
    );
    write(&dir, "mapped.ssd", &ssd);
    let s = read_ssp(&dir.join("mapped.ssd"), &ImportOptions::default()).unwrap();
    // slope = 2 * (2500 mm/s = 2.5 m/s) + 1 = 6 m/s; k = 3 * 2 + 0.5 = 6.5
    let start = |name: &str| {
        let r = s.system.resolve(name).unwrap();
        s.system.instances[r.instance].start_values.iter().find(|(i, _)| *i == r.index).unwrap().1.clone()
    };
    assert_eq!(start("src.slope"), nigel_cosim::Value::Real(6.0));
    assert_eq!(start("amp.k"), nigel_cosim::Value::Real(6.5));
    // the entry with source "" names no parameter of the set: a note, nothing applied
    assert!(s.notes.iter().any(|n| n.contains("map.ssm") && n.contains("apply nothing")), "{:?}", s.notes);
    assert!(
        s.applied.iter().any(|a| a.starts_with("src.slope = 6") && a.contains("from 2500 mm/s")),
        "{:?}",
        s.applied
    );
    // amp.y(1 s) = k * slope * 1 s = 6.5 * 6 = 39
    assert_eq!(last(&dir.join("mapped.ssd"), "amp.y", 1.0, 0.5), 39.0);

    // the same mapping inline, the set inline, with a prefix ("src." prepended to "slope")
    let inline = format!(
        r#"{HEAD}<ssd:System name="root">
  <ssd:ParameterBindings><ssd:ParameterBinding prefix="src.">
    <ssd:ParameterValues><ssv:ParameterSet version="1.0" name="i"><ssv:Parameters>
      <ssv:Parameter name="slope"><ssv:Real value="4"/></ssv:Parameter>
    </ssv:Parameters></ssv:ParameterSet></ssd:ParameterValues>
    <ssd:ParameterMapping><ssm:ParameterMapping version="1.0">
      <ssm:MappingEntry source="src.slope" target="src.slope"><ssc:LinearTransformation factor="0.5"/></ssm:MappingEntry>
    </ssm:ParameterMapping></ssd:ParameterMapping>
  </ssd:ParameterBinding></ssd:ParameterBindings>
  <ssd:Elements><ssd:Component name="src" source="source.fmu"/></ssd:Elements>
</ssd:System></ssd:SystemStructureDescription>"#
    );
    write(&dir, "inline.ssd", &inline);
    // y(1 s) = (0.5 * 4 + 0) * 1 s = 2
    assert_eq!(last(&dir.join("inline.ssd"), "src.y", 1.0, 0.5), 2.0);

    // a value in a unit of another dimension is refused, naming the variable and units
    write(
        &dir,
        "values.ssv",
        &std::fs::read_to_string(dir.join("values.ssv")).unwrap().replace(r#"s="-1" factor"#, r#"s="-2" factor"#),
    );
    let e = read_ssp(&dir.join("mapped.ssd"), &ImportOptions::default()).err().expect("refused").to_string();
    assert!(e.contains("src.slope") && e.contains("different dimensions"), "{e}");
}

#[test]
fn system_connector_values_binding_priority_and_direction() {
    let dir = work_dir_with_source_and_gain("ssp-connectors");
    // root.ssv: the system parameter K, the system input U, amp.k (overridden by K through
    // the connection), src.slope (wins over the component's own binding), and a name
    // that matches nothing (ignored with a note)
    write(
        &dir,
        "root.ssv",
        r#"<ssv:ParameterSet xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" version="1.0" name="r"><ssv:Parameters>
  <ssv:Parameter name="K"><ssv:Real value="3"/></ssv:Parameter>
  <ssv:Parameter name="U"><ssv:Real value="1.5"/></ssv:Parameter>
  <ssv:Parameter name="amp.k"><ssv:Real value="7"/></ssv:Parameter>
  <ssv:Parameter name="src.slope"><ssv:Real value="4"/></ssv:Parameter>
  <ssv:Parameter name="nobody.k"><ssv:Real value="1"/></ssv:Parameter>
  <ssv:Parameter name="Y"><ssv:Real value="5"/></ssv:Parameter>
</ssv:Parameters></ssv:ParameterSet>"#,
    );
    // connections written sink first (end = source) and with startElement="" for the system
    let ssd = format!(
        r#"{HEAD}<ssd:System name="top">
  <ssd:Connectors>
    <ssd:Connector name="K" kind="parameter"><ssc:Real/></ssd:Connector>
    <ssd:Connector name="U" kind="input"><ssc:Real/></ssd:Connector>
    <ssd:Connector name="Y" kind="output"><ssc:Real/></ssd:Connector>
  </ssd:Connectors>
  <ssd:ParameterBindings><ssd:ParameterBinding source="root.ssv"/></ssd:ParameterBindings>
  <ssd:Elements>
    <ssd:Component name="src" source="source.fmu">
      <ssd:ParameterBindings><ssd:ParameterBinding><ssd:ParameterValues><ssv:ParameterSet version="1.0" name="c"><ssv:Parameters>
        <ssv:Parameter name="slope"><ssv:Real value="2"/></ssv:Parameter>
      </ssv:Parameters></ssv:ParameterSet></ssd:ParameterValues></ssd:ParameterBinding></ssd:ParameterBindings>
    </ssd:Component>
    <ssd:Component name="amp" source="gain.fmu"/>
    <ssd:Component name="amp2" source="gain.fmu"/>
  </ssd:Elements>
  <ssd:Connections>
    <ssd:Connection startElement="amp" startConnector="k" endElement="" endConnector="K"/>
    <ssd:Connection startElement="" startConnector="U" endElement="amp" endConnector="u"/>
    <ssd:Connection startElement="amp2" startConnector="u" endElement="src" endConnector="y"/>
    <ssd:Connection startConnector="Y" endElement="amp" endConnector="y"/>
  </ssd:Connections>
</ssd:System></ssd:SystemStructureDescription>"#
    );
    write(&dir, "sys.ssd", &ssd);
    let s = read_ssp(&dir.join("sys.ssd"), &ImportOptions::default()).unwrap();
    // the one FMU-to-FMU connection, src.y -> amp2.u, read from its end
    assert_eq!(s.system.connections.len(), 1);
    assert_eq!(s.system.name_of(&s.system.connections[0].from), "src.y");
    assert!(s.notes.iter().any(|n| n.contains("nobody.k") && n.contains("ignored")), "{:?}", s.notes);
    assert!(s.notes.iter().all(|n| !n.contains("amp.k")), "{:?}", s.notes);
    // the output connector Y is fed by amp.y: a value bound to it is not used, and said so
    assert!(
        s.notes.iter().any(|n| n.contains("connector Y of root system \"top\" is fed by a connection")),
        "{:?}",
        s.notes
    );
    let at_1s = |column: &str| last(&dir.join("sys.ssd"), column, 1.0, 0.5);
    // amp.k = K = 3 (the connection wins over root.ssv's amp.k = 7); amp.u = U = 1.5
    assert_eq!(at_1s("amp.k"), 3.0);
    assert_eq!(at_1s("amp.u"), 1.5);
    // amp.y = 3 * 1.5 = 4.5
    assert_eq!(at_1s("amp.y"), 4.5);
    // src.slope = 4 (the system's binding wins over the component's 2): y(1 s) = 4;
    // amp2.u = src.y = 4, amp2.y = 2 (its default k) * 4 = 8
    assert_eq!(at_1s("src.y"), 4.0);
    assert_eq!(at_1s("amp2.y"), 8.0);
}

#[test]
fn default_start_time_version_note_and_info() {
    let dir = work_dir("ssp-start");
    build_fmu(Model::Source, &dir, &[]);
    let xml_mm =
        Model::Gain.model_description().replace(r#"<Real start="0" unit="m"/>"#, r#"<Real start="0" unit="mm"/>"#);
    build_fmu_with(Model::Gain, &dir, "gain_mm", &xml_mm);
    let ssd = format!(
        r#"{HEAD}<ssd:System name="top">
  <ssd:Elements><ssd:Component name="src" source="source.fmu"/><ssd:Component name="amp" source="gain_mm.fmu"/></ssd:Elements>
  <ssd:Connections><ssd:Connection startElement="src" startConnector="y" endElement="amp" endConnector="u"><ssc:LinearTransformation offset="1"/></ssd:Connection></ssd:Connections>
</ssd:System><ssd:DefaultExperiment startTime="2" stopTime="3"/></ssd:SystemStructureDescription>"#
    )
    .replace(r#"version="1.0" name="t""#, r#"version="2.0" name="t""#);
    let ssp = dir.join("start.ssp");
    pack_ssp(&ssp, ssd, &dir, &["source.fmu", "gain_mm.fmu"]);
    let cosim = |args: &[&str]| std::process::Command::new(env!("CARGO_BIN_EXE_cosim")).args(args).output().unwrap();
    let csv = dir.join("out.csv");
    let out = cosim(&[
        "run",
        ssp.to_str().unwrap(),
        "--step",
        "0.5",
        "--algorithm",
        "ordered",
        "-o",
        csv.to_str().unwrap(),
        "--record",
        "amp.u",
    ]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("version=\"2.0\""), "{stderr}");
    // from the SSD's start 2 s to its stop 3 s; amp.u = 1000 * (1 * t) + 1 [m -> mm, then + 1]
    let text = std::fs::read_to_string(&csv).unwrap();
    let rows: Vec<&str> = text.lines().skip(1).collect();
    assert_eq!(rows, ["2,2001", "2.5,2501", "3,3001"]);
    // --start-time wins over the SSD's
    let out =
        cosim(&["run", ssp.to_str().unwrap(), "--step", "0.5", "--start-time", "2.5", "-o", csv.to_str().unwrap()]);
    assert!(out.status.success());
    assert!(std::fs::read_to_string(&csv).unwrap().lines().nth(1).unwrap().starts_with("2.5,"));
    // cosim info shows the experiment, the conversion and the note
    let info = String::from_utf8_lossy(&cosim(&["info", ssp.to_str().unwrap()]).stdout).into_owned();
    assert!(info.contains("root system \"top\""), "{info}");
    assert!(info.contains("start 2 s (DefaultExperiment), stop 3 s (DefaultExperiment)"), "{info}");
    assert!(
        info.contains(
            "connection src.y [m] -> amp.u [mm]  (x 1000 + 1: unit conversion, then LinearTransformation x 1 + 1)"
        ),
        "{info}"
    );
    assert!(info.contains("note: the SSD says version=\"2.0\""), "{info}");
}

#[test]
fn an_algebraic_loop_at_initialization_is_iterated_to_its_fixed_point_and_a_chain_is_not() {
    let dir = work_dir_with_source_and_gain("ssp-init-loop");
    // a.y = k u depends on a.u (the gain's ModelStructure: y depends on u), likewise b:
    // a.y -> b.u (+ 1, a LinearTransformation) and b.y -> a.u close a loop through both
    // FMUs' direct feedthrough
    let ssd = |connections: &str| {
        format!(
            r#"{HEAD}<ssd:System name="top">
  <ssd:Elements><ssd:Component name="src" source="source.fmu"/><ssd:Component name="a" source="gain.fmu"/><ssd:Component name="b" source="gain.fmu"/></ssd:Elements>
  <ssd:Connections>{connections}</ssd:Connections>
</ssd:System></ssd:SystemStructureDescription>"#
        )
    };
    write(
        &dir,
        "loop.ssd",
        &ssd(
            r#"<ssd:Connection startElement="a" startConnector="y" endElement="b" endConnector="u"><ssc:LinearTransformation offset="1"/></ssd:Connection><ssd:Connection startElement="b" startConnector="y" endElement="a" endConnector="u"/>"#,
        ),
    );
    let cosim = |args: &[&str]| std::process::Command::new(env!("CARGO_BIN_EXE_cosim")).args(args).output().unwrap();
    let ssd_path = dir.join("loop.ssd");
    let csv = dir.join("loop.csv");
    let run = |k: &str| {
        cosim(&[
            "run",
            ssd_path.to_str().unwrap(),
            "--stop-time",
            "0.1",
            "--step",
            "0.1",
            "--set",
            &format!("a.k={k}"),
            "--set",
            &format!("b.k={k}"),
            "--record",
            "a.u",
            "--record",
            "b.u",
            "-o",
            csv.to_str().unwrap(),
        ])
    };
    let out = run("0.5");
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("a.y -> b.u")
            && stderr.contains("b.y -> a.u")
            && stderr.contains("iterated to its fixed point"),
        "{stderr}"
    );
    // the fixed point by hand, k = 0.5: b.u = a.y + 1 = 0.5 a.u + 1 and a.u = b.y = 0.5 b.u,
    // so a.u = 0.25 a.u + 0.5: a.u = 2/3, b.u = 4/3 (carried once, from the start values
    // u = 0, they would be a.u = 0, b.u = 1). Each sweep shrinks the error 4 times; the
    // sweeps stop once a change is below 1e-10 of the value: the error left is below
    // 1e-10 / 3 of it, so 1e-9 absolute holds.
    let text = std::fs::read_to_string(&csv).unwrap();
    let first: Vec<f64> = text.lines().nth(1).unwrap().split(',').map(|x| x.parse().unwrap()).collect();
    assert_eq!(first[0], 0.0);
    assert!((first[1] - 2.0 / 3.0).abs() < 1e-9, "a.u = {}", first[1]);
    assert!((first[2] - 4.0 / 3.0).abs() < 1e-9, "b.u = {}", first[2]);
    // k = 2: a.u = 4 a.u + 2 diverges from every start but its fixed point: refused by name
    let out = run("2");
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success());
    assert!(
        stderr.contains("the algebraic loop at initialization a.y -> b.u, b.y -> a.u did not converge"),
        "{stderr}"
    );
    // src.y depends on nothing: src -> a -> b is a chain, no loop
    write(
        &dir,
        "chain.ssd",
        &ssd(
            r#"<ssd:Connection startElement="src" startConnector="y" endElement="a" endConnector="u"/><ssd:Connection startElement="a" startConnector="y" endElement="b" endConnector="u"/>"#,
        ),
    );
    let s = read_ssp(&dir.join("chain.ssd"), &ImportOptions::default()).unwrap();
    assert!(nigel_cosim::loops::initialization_loop(&s.system).is_none());
}

#[test]
fn a_chain_of_direct_feedthrough_enters_its_first_row_at_its_sources_values() {
    // src -> a -> b -> c, each connection written sink first (as OMSimulator's
    // AircraftVehicleDemonstrator script writes 109 of them), gains k = 2 with y = k u
    // (direct feedthrough), from t0 = 2 s, Jacobi (the default: connections delayed by one
    // step after the first row)
    let dir = work_dir_with_source_and_gain("ssp-init-chain");
    let ssd = format!(
        r#"{HEAD}<ssd:System name="top">
  <ssd:Elements><ssd:Component name="src" source="source.fmu"/><ssd:Component name="a" source="gain.fmu"/><ssd:Component name="b" source="gain.fmu"/><ssd:Component name="c" source="gain.fmu"/></ssd:Elements>
  <ssd:Connections><ssd:Connection startElement="a" startConnector="u" endElement="src" endConnector="y"/><ssd:Connection startElement="b" startConnector="u" endElement="a" endConnector="y"/><ssd:Connection startElement="c" startConnector="u" endElement="b" endConnector="y"/></ssd:Connections>
</ssd:System></ssd:SystemStructureDescription>"#
    );
    write(&dir, "chain.ssd", &ssd);
    let s = read_ssp(&dir.join("chain.ssd"), &ImportOptions::default()).unwrap();
    assert!(nigel_cosim::loops::initialization_loop(&s.system).is_none());
    let mut e = Experiment::new(2.5, 0.5);
    e.start_time = 2.0;
    e.algorithm = Algorithm::Jacobi;
    e.record = Some(["a.u", "b.u", "c.u"].map(String::from).to_vec());
    let (r, _) = simulate(&s.system, &e).unwrap();
    let column = |name: &str| r.column(name).unwrap();
    // the first row, t = 2 s, every input at its source's value when Initialization Mode
    // ends: a.u = src.y = slope t = 1 * 2 = 2; b.u = a.y = 2 * 2 = 4; c.u = b.y = 2 * 4 = 8
    // (carried once from the start values u = 0, c.u would be b.y of b.u = 0, that is 0)
    assert_eq!((column("a.u")[0], column("b.u")[0], column("c.u")[0]), (2.0, 4.0, 8.0));
    // t = 2.5 s, Jacobi: an input row holds the value its instance stepped from 2 s with
    // (the values got at 2.5 s are set before the next step), the consistent 2, 4, 8 again
    assert_eq!((column("a.u")[1], column("b.u")[1], column("c.u")[1]), (2.0, 4.0, 8.0));
}

#[test]
fn a_loop_the_fmus_do_not_declare_at_initialization_is_iterated_too_or_named_when_it_diverges() {
    // gains y = k u whose InitialUnknowns say y depends on nothing at initialization while
    // their Outputs say it depends on u (as the AircraftVehicleDemonstrator's Dymola FMUs
    // declare their ports): a.y -> b.u (+ 1) and b.y -> a.u are no loop by the declarations
    let dir = work_dir("ssp-init-undeclared");
    let xml = Model::Gain.model_description().replace(
        r#"<Outputs><Unknown index="2" dependencies="1"/></Outputs>"#,
        r#"<Outputs><Unknown index="2" dependencies="1"/></Outputs><InitialUnknowns><Unknown index="2" dependencies=""/></InitialUnknowns>"#,
    );
    assert!(xml.contains("<InitialUnknowns>"));
    build_fmu_with(Model::Gain, &dir, "gain", &xml);
    write(
        &dir,
        "loop.ssd",
        &format!(
            r#"{HEAD}<ssd:System name="top">
  <ssd:Elements><ssd:Component name="a" source="gain.fmu"/><ssd:Component name="b" source="gain.fmu"/></ssd:Elements>
  <ssd:Connections><ssd:Connection startElement="a" startConnector="y" endElement="b" endConnector="u"><ssc:LinearTransformation offset="1"/></ssd:Connection><ssd:Connection startElement="b" startConnector="y" endElement="a" endConnector="u"/></ssd:Connections>
</ssd:System></ssd:SystemStructureDescription>"#
        ),
    );
    let s = read_ssp(&dir.join("loop.ssd"), &ImportOptions::default()).unwrap();
    assert!(nigel_cosim::loops::initialization_loop(&s.system).is_none());
    let csv = dir.join("loop.csv");
    let run = |k: &str| {
        let (ssd, out) = (dir.join("loop.ssd"), csv.to_str().unwrap());
        let (ka, kb) = (format!("a.k={k}"), format!("b.k={k}"));
        let args = ["run", ssd.to_str().unwrap(), "--stop-time", "0.1", "--step", "0.1", "--set", &ka, "--set", &kb];
        let args = [&args[..], &["--record", "a.u", "--record", "b.u", "-o", out]].concat();
        std::process::Command::new(env!("CARGO_BIN_EXE_cosim")).args(args).output().unwrap()
    };
    // k = 0.5: the fixed point by hand (as in the declared loop's test): a.u = 0.25 a.u + 0.5,
    // a.u = 2/3, b.u = 4/3; each sweep shrinks the error 4 times and the sweeps stop once a
    // change is below 1e-10 of the value, so the error left is below 1e-10 / 3 of it
    let out = run("0.5");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&csv).unwrap();
    let first: Vec<f64> = text.lines().nth(1).unwrap().split(',').map(|x| x.parse().unwrap()).collect();
    assert!((first[1] - 2.0 / 3.0).abs() < 1e-9, "a.u = {}", first[1]);
    assert!((first[2] - 4.0 / 3.0).abs() < 1e-9, "b.u = {}", first[2]);
    // k = 2: a.u = 4 a.u + 2 diverges: refused, saying what was not declared
    let out = run("2");
    let message = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(message.contains("no algebraic loop by the FMUs' declared dependencies"), "{message}");
    assert!(message.contains("did not converge"), "{message}");
}
