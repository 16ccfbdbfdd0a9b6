//! The C-ABI checks every FMU of `build-fmu`'s list must pass, over the built archives
//! (`target/fmu/manifest.json`, which must equal the list: a new FMU is covered as soon as
//! it is one entry there).

use std::ffi::{c_char, c_int, c_void};
use std::ptr::null_mut;

use model_description::{Causality, Initial, ModelDescription, VariableType};
use nigel_integration_tests::{built_fmu, target_dir, Fmu, Instance, CO_SIMULATION, ERROR, MODEL_EXCHANGE, OK};

/// Every FMU of the list, loaded from its built archive.
fn every_fmu() -> Vec<Fmu> {
    let targets = build_fmu::targets();
    let manifest_path = target_dir().join("fmu").join("manifest.json");
    let manifest = std::fs::read_to_string(&manifest_path)
        .unwrap_or_else(|e| panic!("{}: {e} (run `cargo run --release -p build-fmu`)", manifest_path.display()));
    // the platforms are whatever this machine's toolchains built (the platform tests check
    // them); the FMUs, GUIDs and interfaces must be the declarations' own
    let json: serde_json::Value = serde_json::from_str(&manifest).expect("manifest.json is JSON");
    let platforms: Vec<build_fmu::PlatformBuild> = json[0]["platforms"]
        .as_array()
        .expect("manifest.json lists each FMU's platforms")
        .iter()
        .map(|p| build_fmu::PlatformBuild {
            platform: build_fmu::Platform::from_folder(p["folder"].as_str().unwrap_or_default())
                .unwrap_or_else(|| panic!("manifest.json: unknown platform {}", p["folder"])),
            minimum_os: p["minimum_os"].as_str().unwrap_or_default().to_string(),
            c_library: p["c_library"].as_str().unwrap_or_default().to_string(),
            tested: p["tested"].as_str().unwrap_or_default().to_string(),
        })
        .collect();
    assert_eq!(manifest, build_fmu::manifest(&targets, &platforms), "target/fmu is stale: rebuild with build-fmu");
    assert!(!targets.is_empty());
    targets
        .iter()
        .map(|t| {
            let fmu = Fmu::load(&built_fmu(&t.model_identifier).unwrap()).unwrap();
            assert_eq!(&fmu.description, t.description, "{}: archive XML is the declaration's", t.model_identifier);
            fmu
        })
        .collect()
}

fn id(md: &ModelDescription) -> String {
    md.co_simulation
        .as_ref()
        .map(|c| c.model_identifier.clone())
        .unwrap_or_else(|| md.model_exchange.as_ref().map(|m| m.model_identifier.clone()).unwrap_or_default())
}

fn kinds(md: &ModelDescription) -> Vec<c_int> {
    let mut k = Vec::new();
    if md.co_simulation.is_some() {
        k.push(CO_SIMULATION);
    }
    if md.model_exchange.is_some() {
        k.push(MODEL_EXCHANGE);
    }
    k
}

/// Reals settable before initialization (inputs and exact parameters/states), with a
/// value inside their bounds that differs from the start value.
fn settable_reals(md: &ModelDescription) -> Vec<(String, u32, f64, f64)> {
    md.model_variables
        .iter()
        .filter(|v| v.causality == Causality::Input || v.initial == Some(Initial::Exact))
        .filter_map(|v| match &v.variable_type {
            VariableType::Real { start: Some(start), min, max, .. } => {
                let mut other = start + 0.01 * (1.0 + start.abs());
                if max.is_some_and(|m| other > m) || min.is_some_and(|m| other < m) {
                    other = start - 0.01 * (1.0 + start.abs());
                }
                if max.is_some_and(|m| other > m) || min.is_some_and(|m| other < m) {
                    return None;
                }
                Some((v.name.clone(), v.value_reference, *start, other))
            }
            _ => None,
        })
        .collect()
}

#[test]
fn all_44_symbols_and_the_right_guid_only() {
    for fmu in every_fmu() {
        let md = &fmu.description;
        for kind in kinds(md) {
            let (bad, log) = fmu.instantiate("wrong", kind, "{00000000-0000-0000-0000-000000000000}");
            assert!(bad.is_none(), "{}: wrong GUID accepted", id(md));
            assert!(log.last_error().unwrap().contains("fmuGUID"), "{}", id(md));
            let (good, log) = fmu.instantiate("right", kind, fmu.guid());
            assert!(good.is_some(), "{}: {:?}", id(md), log.last_error());
        }
        // an interface not offered is refused
        for (kind, offered) in
            [(MODEL_EXCHANGE, md.model_exchange.is_some()), (CO_SIMULATION, md.co_simulation.is_some())]
        {
            if !offered {
                assert!(fmu.instantiate("x", kind, fmu.guid()).0.is_none(), "{}", id(md));
            }
        }
    }
}

#[test]
fn illegal_call_orders_are_errors_and_reset_recovers() {
    for fmu in every_fmu() {
        let md = &fmu.description;
        for kind in kinds(md) {
            let (i, log) = fmu.instantiate("orders", kind, fmu.guid());
            let i = i.unwrap();
            let f = i.f();
            let any_real = md.model_variables.iter().find(|v| v.variable_type.type_name() == "Real");
            if let Some(v) = any_real {
                assert_eq!(i.get_real(&[v.value_reference]), Err(ERROR), "{}: GetReal before initialization", id(md));
                assert!(log.last_error().unwrap().contains("not allowed in state Instantiated"));
                assert_eq!(i.reset(), OK);
            }
            assert_eq!(i.exit_init(), ERROR, "{}: exit before enter", id(md));
            assert_eq!(i.reset(), OK);
            let mut info = nigel_integration_tests::EventInfo::default();
            let early = unsafe {
                if kind == CO_SIMULATION {
                    (f.do_step.unwrap())(i.c, 0.0, 1e-3, 1)
                } else {
                    (f.new_discrete_states.unwrap())(i.c, &mut info)
                }
            };
            assert_eq!(early, ERROR, "{}: step/event before initialization", id(md));
            assert_eq!(i.reset(), OK);
            i.initialize();
            assert_eq!(i.enter_init(), ERROR, "{}: enterInitializationMode twice", id(md));
            // the other interface's functions
            let other = unsafe {
                if kind == CO_SIMULATION {
                    (f.enter_continuous_time_mode.unwrap())(i.c)
                } else {
                    (f.do_step.unwrap())(i.c, 0.0, 1e-3, 1)
                }
            };
            assert_eq!(other, ERROR);
            assert_eq!(i.reset(), OK);
            i.initialize();
            assert_eq!(i.terminate(), OK);
            assert_eq!(i.terminate(), ERROR, "{}: terminate twice", id(md));
            assert_eq!(i.reset(), OK);
            i.initialize();
        }
    }
}

#[test]
fn nan_and_inf_are_refused_naming_the_variable() {
    for fmu in every_fmu() {
        let md = &fmu.description;
        let (i, log) = fmu.instantiate("nan", CO_SIMULATION.min(kinds(md)[0]), fmu.guid());
        let i = i.unwrap();
        let reals = settable_reals(md);
        assert!(!reals.is_empty());
        for (name, vr, start, _) in &reals {
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                assert_eq!(i.set_real(&[*vr], &[bad]), ERROR, "{}: {name} = {bad}", id(md));
                let msg = log.last_error().unwrap();
                assert!(msg.contains("fmi2SetReal") && msg.contains(name.as_str()), "{msg}");
                assert_eq!(i.reset(), OK);
            }
            // not applied: the start value is still there
            assert_eq!(i.enter_init(), OK);
            assert_eq!(i.get_real(&[*vr]).unwrap(), vec![*start], "{name}");
            assert_eq!(i.reset(), OK);
        }
    }
}

unsafe fn serialize(i: &Instance, state: *mut c_void) -> Vec<u8> {
    let mut size = 0usize;
    assert_eq!((i.f().serialized_fmu_state_size.unwrap())(i.c, state, &mut size), OK);
    let mut bytes = vec![0u8; size];
    assert_eq!((i.f().serialize_fmu_state.unwrap())(i.c, state, bytes.as_mut_ptr() as *mut c_char, size), OK);
    bytes
}

#[test]
fn fmu_state_round_trip_is_bit_exact() {
    for fmu in every_fmu() {
        let md = &fmu.description;
        let Some(cs) = &md.co_simulation else { continue };
        if !cs.can_serialize_fmu_state {
            continue;
        }
        let inputs: Vec<(String, u32, f64, f64)> = settable_reals(md)
            .into_iter()
            .filter(|(name, ..)| md.variable(name).is_some_and(|v| v.causality == Causality::Input))
            .collect();
        let outputs: Vec<u32> = md
            .model_structure
            .outputs
            .iter()
            .map(|u| &md.model_variables[u.index as usize - 1])
            .filter(|v| v.variable_type.type_name() == "Real")
            .map(|v| v.value_reference)
            .collect();
        let step = md.default_experiment.as_ref().and_then(|d| d.step_size).unwrap_or(1e-3);
        let drive = |i: &Instance, t0: f64, n: usize| -> Vec<u64> {
            let mut bits = Vec::new();
            for k in 0..n {
                let t = t0 + k as f64 * step;
                let phase = (k % 3) as f64 / 2.0;
                let vrs: Vec<u32> = inputs.iter().map(|x| x.1).collect();
                let values: Vec<f64> = inputs.iter().map(|x| x.2 + (x.3 - x.2) * phase).collect();
                assert_eq!(i.set_real(&vrs, &values), OK);
                assert_eq!(i.do_step(t, step), OK, "{}", id(md));
                bits.extend(i.get_real(&outputs).unwrap().into_iter().map(f64::to_bits));
            }
            bits
        };
        let (a, _) = fmu.instantiate("a", CO_SIMULATION, fmu.guid());
        let a = a.unwrap();
        a.initialize();
        drive(&a, 0.0, 7);
        let mut state = null_mut();
        let bytes = unsafe {
            assert_eq!((a.f().get_fmu_state.unwrap())(a.c, &mut state), OK);
            serialize(&a, state)
        };
        let t1 = 7.0 * step;
        let first = drive(&a, t1, 25);
        // in memory
        unsafe { assert_eq!((a.f().set_fmu_state.unwrap())(a.c, state), OK) };
        assert_eq!(drive(&a, t1, 25), first, "{}: in-memory state", id(md));
        // through bytes, into a fresh instance that was never initialized
        let (b, log) = fmu.instantiate("b", CO_SIMULATION, fmu.guid());
        let b = b.unwrap();
        let mut copy = null_mut();
        unsafe {
            assert_eq!(
                (b.f().deserialize_fmu_state.unwrap())(b.c, bytes.as_ptr() as *const c_char, bytes.len(), &mut copy),
                OK,
                "{:?}",
                log.last_error()
            );
            assert_eq!((b.f().set_fmu_state.unwrap())(b.c, copy), OK);
            // and serializing the copy gives the same bytes
            assert_eq!(serialize(&b, copy), bytes);
        }
        assert_eq!(drive(&b, t1, 25), first, "{}: serialized state", id(md));
        // a state of one instance is not accepted by another
        unsafe { assert_eq!((b.f().set_fmu_state.unwrap())(b.c, state), ERROR) };
    }
}

#[test]
fn every_measured_input_to_output_dependency_is_declared() {
    // At a random point inside the bounds, each input is perturbed alone; an output that
    // changes at the same instant (direct feed-through, or through the initial event of a
    // sampled model) must list that input in ModelStructure/Outputs.
    for fmu in every_fmu() {
        let md = &fmu.description;
        if md.co_simulation.is_none() {
            continue;
        }
        // inputs and exact states, parameters at their start values
        let reals: Vec<_> = settable_reals(md)
            .into_iter()
            .filter(|x| md.variable(&x.0).is_some_and(|v| v.causality != Causality::Parameter))
            .collect();
        let inputs: Vec<&(String, u32, f64, f64)> =
            reals.iter().filter(|x| md.variable(&x.0).is_some_and(|v| v.causality == Causality::Input)).collect();
        let outputs: Vec<(u32, u32, Option<Vec<u32>>)> = md
            .model_structure
            .outputs
            .iter()
            .filter(|u| md.model_variables[u.index as usize - 1].variable_type.type_name() == "Real")
            .map(|u| (u.index, md.model_variables[u.index as usize - 1].value_reference, u.dependencies.clone()))
            .collect();
        let out_vrs: Vec<u32> = outputs.iter().map(|o| o.1).collect();
        let base: Vec<f64> =
            reals.iter().enumerate().map(|(k, x)| x.2 + (x.3 - x.2) * (0.3 + 0.07 * k as f64 % 1.0)).collect();
        let evaluate = |perturbed: Option<u32>| -> Vec<f64> {
            let (i, log) = fmu.instantiate("deps", CO_SIMULATION, fmu.guid());
            let i = i.unwrap();
            let vrs: Vec<u32> = reals.iter().map(|x| x.1).collect();
            let mut values = base.clone();
            if let Some(vr) = perturbed {
                let k = reals.iter().position(|x| x.1 == vr).unwrap();
                values[k] = reals[k].3 + (reals[k].2 - reals[k].3) * 0.5;
            }
            assert_eq!(i.set_real(&vrs, &values), OK, "{:?}", log.last_error());
            i.initialize();
            i.get_real(&out_vrs).unwrap()
        };
        let reference = evaluate(None);
        let mut seen = 0;
        for input in &inputs {
            let index = md.model_variables.iter().position(|v| v.name == input.0).unwrap() as u32 + 1;
            let changed = evaluate(Some(input.1));
            for (k, (out_index, _, deps)) in outputs.iter().enumerate() {
                if changed[k] != reference[k] {
                    seen += 1;
                    if let Some(deps) = deps {
                        assert!(
                            deps.contains(&index),
                            "{}: {} changes with {} but does not declare it",
                            id(md),
                            md.model_variables[*out_index as usize - 1].name,
                            input.0
                        );
                    }
                }
            }
        }
        assert!(seen > 0 || inputs.is_empty(), "{}: no output reacts to any input", id(md));
    }
}

#[test]
fn hostile_lengths_and_strings_are_errors_naming_the_function() {
    for fmu in every_fmu() {
        let md = &fmu.description;
        let (i, log) = fmu.instantiate("lengths", kinds(md)[0], fmu.guid());
        let i = i.unwrap();
        i.initialize();
        let f = i.f();
        let vr = [0u32; 2];
        let mut out = [0.0f64; 2];
        // a length of 2^40 with a two-element buffer: refused before anything is read
        let s = unsafe { (f.get_real)(i.c, vr.as_ptr(), 1 << 40, out.as_mut_ptr()) };
        assert_eq!(s, ERROR);
        let msg = log.last_error().unwrap();
        assert!(msg.contains("fmi2GetReal") && msg.contains("1099511627776"), "{msg}");
        assert_eq!(i.reset(), OK);
        i.initialize();
        // the model has no String variables: fmi2SetString reports under its own name
        let text = [c"x".as_ptr()];
        let s = unsafe { (f.set_string)(i.c, vr.as_ptr(), 1, text.as_ptr()) };
        assert_eq!(s, ERROR);
        let msg = log.last_error().unwrap();
        assert!(msg.starts_with("fmi2SetString:"), "{msg}");
    }
}

/// Our models declare (`Model::setter_may_refuse`) that their inputs have no check beyond
/// the layer's, so `fmi2SetReal` of inputs keeps no earlier values for the way back: every
/// value inside an input's declared bounds must then be accepted, in one batch of all
/// inputs (in initialization mode), and read back unchanged.
#[test]
fn every_real_input_accepts_every_value_inside_its_declared_bounds() {
    for fmu in every_fmu() {
        let md = &fmu.description;
        let inputs: Vec<(String, u32, f64, f64)> = md
            .model_variables
            .iter()
            .filter(|v| v.causality == Causality::Input)
            .filter_map(|v| match &v.variable_type {
                VariableType::Real { min, max, .. } => {
                    Some((v.name.clone(), v.value_reference, min.unwrap_or(-1e300), max.unwrap_or(1e300)))
                }
                _ => None,
            })
            .collect();
        assert!(!inputs.is_empty(), "{}", id(md));
        let vrs: Vec<u32> = inputs.iter().map(|x| x.1).collect();
        let picks = |k: usize| -> Vec<f64> {
            inputs
                .iter()
                .map(|(_, _, lo, hi)| match k {
                    0 => *lo,
                    1 => *hi,
                    2 => 0.0f64.clamp(*lo, *hi),
                    3 => (-f64::MIN_POSITIVE).clamp(*lo, *hi),
                    _ => 0.5 * lo + 0.5 * hi,
                })
                .collect()
        };
        let (i, log) = fmu.instantiate("inputs", CO_SIMULATION.min(kinds(md)[0]), fmu.guid());
        let i = i.unwrap();
        assert_eq!(i.enter_init(), OK);
        for k in 0..5 {
            let values = picks(k);
            assert_eq!(i.set_real(&vrs, &values), OK, "{} pick {k}: {:?}", id(md), log.last_error());
            let back = i.get_real(&vrs).unwrap();
            for ((name, ..), (x, y)) in inputs.iter().zip(values.iter().zip(&back)) {
                assert_eq!(x.to_bits(), y.to_bits(), "{}: {name}", id(md));
            }
        }
    }
}

/// The Real unknowns of one ModelStructure list: (name, value reference, dependencies).
fn real_unknowns(md: &ModelDescription, list: &[model_description::Unknown]) -> Vec<(String, u32, Option<Vec<u32>>)> {
    list.iter()
        .map(|u| (&md.model_variables[u.index as usize - 1], &u.dependencies))
        .filter(|(v, _)| v.variable_type.type_name() == "Real")
        .map(|(v, d)| (v.name.clone(), v.value_reference, d.clone()))
        .collect()
}

/// 1-based index of variable `name` in ModelVariables.
fn index_of(md: &ModelDescription, name: &str) -> u32 {
    md.model_variables.iter().position(|v| v.name == name).map(|p| p as u32 + 1).unwrap()
}

/// Perturbs one known by `change` (which must also undo it when given `false`), reads the
/// unknowns before and after, and checks that every unknown that moved lists the known
/// (or depends on all). Returns how many moved.
fn check_moved(
    md: &ModelDescription,
    what: &str,
    i: &Instance,
    unknowns: &[(String, u32, Option<Vec<u32>>)],
    known: (&str, u32),
    change: &dyn Fn(bool),
) -> usize {
    let vrs: Vec<u32> = unknowns.iter().map(|u| u.1).collect();
    let before = i.get_real(&vrs).unwrap();
    change(true);
    let after = i.get_real(&vrs).unwrap();
    change(false);
    assert_eq!(i.get_real(&vrs).unwrap(), before, "{}: {what}: undoing {} restores the unknowns", id(md), known.0);
    let mut moved = 0;
    for ((name, _, deps), (b, a)) in unknowns.iter().zip(before.iter().zip(&after)) {
        if a.to_bits() != b.to_bits() {
            moved += 1;
            assert!(
                !matches!(deps, Some(d) if !d.contains(&known.1)),
                "{}: {what}: {name} moves with {} ({b} -> {a}) but its dependencies {deps:?} omit index {}",
                id(md),
                known.0,
                known.1
            );
        }
    }
    moved
}

/// The ModelStructure's dependencies, checked numerically for every FMU: perturb each known
/// and see which unknowns move. In Initialization Mode the knowns are the inputs and the
/// exact variables (FMI 2.0 section 2.2.8: parameters, and exact locals such as the
/// controller's `speed_integral`) and the unknowns the InitialUnknowns; after it, the
/// Outputs and Derivatives move only with the inputs and continuous states they list
/// (Co-Simulation between steps; Model Exchange in continuous-time mode). A moving unknown
/// whose list omits the known fails; the totals show the check is not vacuous.
#[test]
fn model_structure_dependencies_are_the_knowns_that_move_the_unknowns() {
    for fmu in every_fmu() {
        let md = &fmu.description;
        let knowns = settable_reals(md);
        let ms = &md.model_structure;

        let (i, _log) = fmu.instantiate("deps-init", kinds(md)[0], fmu.guid());
        let i = i.unwrap();
        assert_eq!(i.setup(0.0), OK);
        assert_eq!(i.enter_init(), OK);
        let initial = real_unknowns(md, &ms.initial_unknowns);
        let mut moved = 0;
        for (name, vr, start, other) in &knowns {
            let set = |on: bool| assert_eq!(i.set_real(&[*vr], &[if on { *other } else { *start }]), OK);
            moved += check_moved(md, "initialization", &i, &initial, (name, index_of(md, name)), &set);
        }
        assert!(moved > 0, "{}: nothing moved in Initialization Mode", id(md));

        let inputs: Vec<_> =
            knowns.iter().filter(|(n, ..)| md.variable(n).is_some_and(|v| v.causality == Causality::Input)).collect();
        let outputs = real_unknowns(md, &ms.outputs);
        let derivatives = real_unknowns(md, &ms.derivatives);
        if md.co_simulation.is_some() {
            let (i, _log) = fmu.instantiate("deps-cs", CO_SIMULATION, fmu.guid());
            let i = i.unwrap();
            i.initialize();
            assert_eq!(i.do_step(0.0, 1e-3), OK);
            for (name, vr, start, other) in &inputs {
                let set = |on: bool| assert_eq!(i.set_real(&[*vr], &[if on { *other } else { *start }]), OK);
                check_moved(md, "Co-Simulation", &i, &outputs, (name, index_of(md, name)), &set);
            }
        }
        if md.model_exchange.is_some() {
            let (i, _log) = fmu.instantiate("deps-me", MODEL_EXCHANGE, fmu.guid());
            let i = i.unwrap();
            i.initialize();
            let mut info = nigel_integration_tests::EventInfo::default();
            unsafe {
                assert_eq!((i.f().new_discrete_states.unwrap())(i.c, &mut info), OK);
                assert_eq!((i.f().enter_continuous_time_mode.unwrap())(i.c), OK);
            }
            let mut unknowns = outputs.clone();
            unknowns.extend(derivatives.iter().cloned());
            let continuous: Vec<_> = inputs
                .iter()
                .filter(|(n, ..)| {
                    md.variable(n).is_some_and(|v| v.variability == model_description::Variability::Continuous)
                })
                .collect();
            for (name, vr, start, other) in continuous {
                let set = |on: bool| assert_eq!(i.set_real(&[*vr], &[if on { *other } else { *start }]), OK);
                check_moved(md, "Model Exchange", &i, &unknowns, (name, index_of(md, name)), &set);
            }
            let nx = derivatives.len();
            let mut x = vec![0.0; nx];
            unsafe { assert_eq!((i.f().get_continuous_states.unwrap())(i.c, x.as_mut_ptr(), nx), OK) };
            for (k, d) in ms.derivatives.iter().enumerate() {
                let Some(VariableType::Real { derivative: Some(state), .. }) =
                    md.model_variables.get(d.index as usize - 1).map(|v| &v.variable_type)
                else {
                    panic!("{}: derivative without its state", id(md))
                };
                let state_name = md.model_variables[*state as usize - 1].name.clone();
                let set = |on: bool| {
                    let mut y = x.clone();
                    if on {
                        y[k] += 1e-3 * (1.0 + y[k].abs());
                    }
                    assert_eq!(unsafe { (i.f().set_continuous_states.unwrap())(i.c, y.as_ptr(), nx) }, OK);
                };
                check_moved(md, "Model Exchange", &i, &unknowns, (&state_name, *state), &set);
            }
        }
    }
}
