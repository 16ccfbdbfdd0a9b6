//! SSP 1.0: export of a Rust-built system and import back; hand-written SSDs with nested
//! systems, .ssv parameter files, linear transformations and units; unsupported parts
//! refused by name. Also writes the system the fmpy cross-check (tests/python) runs.

mod common;
use common::{build_fmu, build_fmu_with, pack_ssp, plant_fmu, work_dir, work_dir_with_source_and_gain, Model};
use nigel_cosim::{read_ssp, simulate, write_ssp, Algorithm, Error, Experiment, Fmu, ImportOptions, SystemBuilder};
use std::path::Path;

fn chain(dir: &Path) -> SystemBuilder {
    let mut b = SystemBuilder::new();
    b.add_instance("src", Fmu::load(&build_fmu(Model::Source, dir, &[])).unwrap()).unwrap();
    b.add_instance("amp", Fmu::load(&build_fmu(Model::Gain, dir, &[])).unwrap()).unwrap();
    b.add_instance("int", Fmu::load(&build_fmu(Model::Integrator, dir, &[])).unwrap()).unwrap();
    b
}

#[test]
fn exported_ssp_reads_back_to_the_same_system_and_results() {
    let dir = work_dir("ssp-export");
    let mut b = chain(&dir);
    b.connect("src.y", "amp.u").unwrap();
    b.connect_linear("amp.y", "int.u", Some((0.5, 0.25))).unwrap();
    b.set_text("amp.k", "3").unwrap();
    b.set_text("src.slope", "1.5").unwrap();
    let system = b.build();
    let ssp = dir.join("chain.ssp");
    write_ssp(&system, "chain", Some(1.0), &ssp).unwrap();
    let back = read_ssp(&ssp, &ImportOptions::default()).unwrap();
    assert_eq!(back.default_start_stop, (Some(0.0), Some(1.0)));
    assert_eq!(back.system.connections, system.connections);
    let names = |s: &nigel_cosim::System| s.instances.iter().map(|i| i.name.clone()).collect::<Vec<_>>();
    assert_eq!(names(&back.system), ["src", "amp", "int"]);
    for algorithm in [Algorithm::Jacobi, Algorithm::Ordered] {
        let mut e = Experiment::new(1.0, 0.1);
        e.algorithm = algorithm;
        let (a, _) = simulate(&system, &e).unwrap();
        let (b, _) = simulate(&back.system, &e).unwrap();
        assert_eq!(a.values, b.values);
        // int.u = 0.5 * (3 * 1.5 t) + 0.25 in ordered mode
        if algorithm == Algorithm::Ordered {
            let x = a.column("int.x").unwrap();
            let t = a.column("time").unwrap();
            let expect: f64 = (0..10).map(|k| (0.5 * (3.0 * 1.5 * t[k]) + 0.25) * (t[k + 1] - t[k])).sum();
            assert!((x[10] - expect).abs() < 1e-14, "{} vs {expect}", x[10]);
        }
    }
}

#[test]
fn writes_the_system_for_the_fmpy_cross_check() {
    // src -> amp -> int, amp.y -> plant.mu_fl; all outputs zero at t = 0 (fmpy's
    // simulate_ssp starts every connection at 0); no parameters (fmpy ignores bindings)
    let dir = work_dir("ssp-fmpy");
    let mut b = chain(&dir);
    b.add_instance("plant", Fmu::load(&plant_fmu()).unwrap()).unwrap();
    b.connect("src.y", "amp.u").unwrap();
    b.connect("amp.y", "int.u").unwrap();
    b.connect("amp.y", "plant.mu_fl").unwrap();
    b.connect("int.x", "plant.wind_side").unwrap_err(); // m -> N refused
    let out = dir.parent().unwrap().join("export");
    std::fs::create_dir_all(&out).unwrap();
    write_ssp(&b.build(), "chain_with_plant", Some(1.0), &out.join("chain_with_plant.ssp")).unwrap();
    let back = read_ssp(&out.join("chain_with_plant.ssp"), &ImportOptions::default()).unwrap();
    assert_eq!(back.system.connections.len(), 3);
}

const SSD_HEAD: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon" xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription" xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" version="1.0" name="t">"#;

#[test]
fn nested_systems_ssv_units_and_default_factor() {
    let dir = work_dir("ssp-nested");
    build_fmu(Model::Source, &dir, &[]);
    build_fmu(Model::Integrator, &dir, &[]);
    let xml_mm =
        Model::Gain.model_description().replace(r#"<Real start="0" unit="m"/>"#, r#"<Real start="0" unit="mm"/>"#);
    build_fmu_with(Model::Gain, &dir, "gain_mm", &xml_mm);
    std::fs::write(
        dir.join("gains.ssv"),
        r#"<?xml version="1.0" encoding="UTF-8"?>
<ssv:ParameterSet xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" version="1.0" name="p">
  <ssv:Parameters>
    <ssv:Parameter name="inner.amp.k"><ssv:Real value="0.5"/></ssv:Parameter>
    <ssv:Parameter name="other.k"><ssv:Real value="99"/></ssv:Parameter>
  </ssv:Parameters>
</ssv:ParameterSet>"#,
    )
    .unwrap();
    // src.y [m] -> (system connector) -> inner.amp.u [mm] (x1000), LinearTransformation
    // with only an offset (factor defaults to 1); inner.amp.y -> int.u through the inner
    // system's output connector; src.slope bound inline
    let ssd = format!(
        r#"{SSD_HEAD}
  <ssd:System name="root">
    <ssd:ParameterBindings>
      <ssd:ParameterBinding source="gains.ssv"/>
    </ssd:ParameterBindings>
    <ssd:Elements>
      <ssd:Component name="src" source="source.fmu">
        <ssd:Connectors><ssd:Connector name="y" kind="output"><ssc:Real/></ssd:Connector></ssd:Connectors>
        <ssd:ParameterBindings><ssd:ParameterBinding><ssd:ParameterValues>
          <ssv:ParameterSet version="1.0" name="s"><ssv:Parameters>
            <ssv:Parameter name="slope"><ssv:Real value="2"/></ssv:Parameter>
          </ssv:Parameters></ssv:ParameterSet>
        </ssd:ParameterValues></ssd:ParameterBinding></ssd:ParameterBindings>
      </ssd:Component>
      <ssd:System name="inner">
        <ssd:Connectors>
          <ssd:Connector name="in" kind="input"/>
          <ssd:Connector name="out" kind="output"/>
        </ssd:Connectors>
        <ssd:Elements>
          <ssd:Component name="amp" source="gain_mm.fmu"/>
        </ssd:Elements>
        <ssd:Connections>
          <ssd:Connection startConnector="in" endElement="amp" endConnector="u"><ssc:LinearTransformation offset="1"/></ssd:Connection>
          <ssd:Connection startElement="amp" startConnector="y" endConnector="out"/>
        </ssd:Connections>
      </ssd:System>
      <ssd:Component name="int" source="integrator.fmu"/>
    </ssd:Elements>
    <ssd:Connections>
      <ssd:Connection startElement="src" startConnector="y" endElement="inner" endConnector="in"/>
      <ssd:Connection startElement="inner" startConnector="out" endElement="int" endConnector="u" suppressUnitConversion="true"/>
    </ssd:Connections>
  </ssd:System>
  <ssd:DefaultExperiment startTime="0" stopTime="2"/>
</ssd:SystemStructureDescription>"#
    );
    let ssd_path = dir.join("nested.ssd");
    std::fs::write(&ssd_path, &ssd).unwrap();
    // "other.k" matches no variable: SSP 1.0 ignores it, cosim says so in a note
    let with_other = read_ssp(&ssd_path, &ImportOptions::default()).unwrap();
    assert!(with_other.notes.iter().any(|n| n.contains("other.k") && n.contains("ignored")), "{:?}", with_other.notes);
    std::fs::write(
        dir.join("gains.ssv"),
        std::fs::read_to_string(dir.join("gains.ssv"))
            .unwrap()
            .replace(r#"<ssv:Parameter name="other.k"><ssv:Real value="99"/></ssv:Parameter>"#, ""),
    )
    .unwrap();
    let s = read_ssp(&ssd_path, &ImportOptions::default()).unwrap();
    let names: Vec<&str> = s.system.instances.iter().map(|i| i.name.as_str()).collect();
    assert_eq!(names, ["src", "inner.amp", "int"]);
    assert_eq!(s.default_start_stop.1, Some(2.0));
    let c = &s.system.connections;
    assert_eq!(c.len(), 2);
    assert_eq!((c[0].gain, c[0].offset), (1000.0, 1.0)); // m -> mm, then + 1 (factor default 1)
    assert_eq!((c[1].gain, c[1].offset), (1.0, 0.0)); // unit conversion suppressed
    let mut e = Experiment::new(1.0, 0.5);
    e.algorithm = Algorithm::Ordered;
    e.record = Some(vec!["inner.amp.u".into(), "inner.amp.y".into(), "int.u".into()]);
    let (r, _) = simulate(&s.system, &e).unwrap();
    // u = 1000 * (2 t) + 1, y = 0.5 u
    assert_eq!(r.column("inner.amp.u").unwrap(), vec![1.0, 1001.0, 2001.0]);
    assert_eq!(r.column("int.u").unwrap(), vec![0.5, 500.5, 1000.5]);

    // the same as an .ssp archive
    let ssp = dir.join("nested.ssp");
    pack_ssp(&ssp, ssd, &dir, &["gains.ssv", "source.fmu", "gain_mm.fmu", "integrator.fmu"]);
    let s2 = read_ssp(&ssp, &ImportOptions::default()).unwrap();
    assert_eq!(simulate(&s2.system, &e).unwrap().0.values, r.values);
}

#[test]
fn bad_ssps_are_refused_by_name() {
    let dir = work_dir_with_source_and_gain("ssp-bad");
    let system = |elements: &str, connections: &str, extra: &str| {
        format!(
            r#"{SSD_HEAD}<ssd:System name="r">
  <ssd:Elements>
    <ssd:Component name="src" source="source.fmu"/>
    <ssd:Component name="amp" source="gain.fmu"/>
    {elements}
  </ssd:Elements>
  <ssd:Connections>{connections}</ssd:Connections>{extra}
</ssd:System></ssd:SystemStructureDescription>"#
        )
    };
    let cases: &[(&str, String, &str)] = &[
        ("unknown variable", system("", r#"<ssd:Connection startElement="src" startConnector="nope" endElement="amp" endConnector="u"/>"#, ""), "nope"),
        ("unknown element", system("", r#"<ssd:Connection startElement="zz" startConnector="y" endElement="amp" endConnector="u"/>"#, ""), "zz"),
        ("two inputs", system("", r#"<ssd:Connection startElement="amp" startConnector="u" endElement="amp" endConnector="k"/>"#, ""), "not an output to an input"),
        ("connector declared twice", system("", "", r#"<ssd:Connectors><ssd:Connector name="c" kind="input"/><ssd:Connector name="c" kind="input"/></ssd:Connectors>"#).replace("<ssd:Elements>", "").replace("</ssd:Elements>", "").replace(r#"<ssd:Component name="src" source="source.fmu"/>"#, "").replace(r#"<ssd:Component name="amp" source="gain.fmu"/>"#, ""), "root system \"r\""),
        (
            "mismatched connector type",
            system("", "", "").replace(r#"<ssd:Component name="src" source="source.fmu"/>"#, r#"<ssd:Component name="src" source="source.fmu"><ssd:Connectors><ssd:Connector name="y" kind="output"><ssc:Boolean/></ssd:Connector></ssd:Connectors></ssd:Component>"#),
            "declared Boolean",
        ),
        (
            "boolean mapping",
            system("", r#"<ssd:Connection startElement="src" startConnector="y" endElement="amp" endConnector="u"><ssc:BooleanMappingTransformation/></ssd:Connection>"#, ""),
            "BooleanMappingTransformation",
        ),
        ("signal dictionary", system("", "", "<ssd:SignalDictionaries/>"), "SignalDictionaries"),
        ("nested ssp", system(r#"<ssd:Component name="sub" source="x.ssp" type="application/x-ssp-package"/>"#, "", ""), "application/x-ssp-package"),
        ("escaping source", system(r#"<ssd:Component name="up" source="../x.fmu"/>"#, "", ""), "refused"),
        ("malformed", "<ssd:SystemStructureDescription><ssd:System".to_string(), "malformed XML"),
        ("not an ssd", "<fmiModelDescription/>".to_string(), "not SystemStructureDescription"),
    ];
    for (what, xml, needle) in cases {
        let p = dir.join("bad.ssd");
        std::fs::write(&p, xml).unwrap();
        match read_ssp(&p, &ImportOptions::default()) {
            Err(e) => {
                let text = e.to_string();
                assert!(text.contains(needle), "{what}: {text:?} does not name {needle:?}");
                if *what == "unknown variable" || *what == "two inputs" {
                    assert!(matches!(e, Error::Connection { .. }), "{what}: {e:?}");
                }
            }
            Ok(_) => panic!("{what}: accepted"),
        }
    }
}
