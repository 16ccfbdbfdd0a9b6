//! Seeded random call sequences over every function of both generations, each FMU in
//! `build-fmu`'s list (one library exports both), Co-Simulation and Model Exchange, in every
//! state, with hostile arguments: one loop (`random/mod.rs`) with each generation's calls
//! (`random/fmi2.rs`: the 44 `fmi2*` functions; `random/fmi3.rs`: the 75 `fmi3*` functions
//! and now and then an `fmi2*` call on the FMI 3.0 instance). Checked after every call: no
//! crash, a defined status, the one state table of `fmi_export::states` respected (a call it
//! forbids returns Error; FMI 3.0's message names the function), and no non-finite number
//! handed out with OK.
//!
//! `NIGEL_RANDOM_SEQUENCES` sets the number of FMI 2.0 sequences per FMU and interface
//! (default 150,000: some 1.2 million calls per interface for the plant, a few seconds),
//! `NIGEL_RANDOM_SEQUENCES3` the FMI 3.0 ones (default 20,000).

mod random;
use random::fmi2::Fmi2;
use random::fmi3::Fmi3;
use random::{every_fmu_and_interface, run};

/// The number of sequences per FMU and interface: `variable`, else `default`.
fn sequences(variable: &str, default: usize) -> usize {
    std::env::var(variable).ok().and_then(|s| s.parse().ok()).unwrap_or(default)
}

#[test]
fn fmi2_random_call_sequences_respect_the_state_table_and_never_hand_out_non_finite_numbers() {
    let sequences = sequences("NIGEL_RANDOM_SEQUENCES", 150_000);
    // the plant's counts per interface, which docs/testing.md prints
    let plant = every_fmu_and_interface("", sequences, 0x9E37_79B9_7F4A_7C15, "nigel_plant", |fmu, cs, seed| {
        run(&Fmi2::new(fmu, cs), cs, sequences, seed)
    });
    if sequences == 150_000 {
        readme_prints_the_plant_counts(&plant);
    }
}

#[test]
fn fmi3_random_call_sequences_respect_the_state_table_and_never_hand_out_non_finite_numbers() {
    let sequences = sequences("NIGEL_RANDOM_SEQUENCES3", 20_000);
    every_fmu_and_interface(" (FMI 3.0)", sequences, 0x3C6E_F372_FE94_F82B, "", |fmu, cs, seed| {
        run(&Fmi3::new(fmu, cs), cs, sequences, seed)
    });
}

/// The figures docs/testing.md prints of the default run (see "Figures in the docs" there): the plant's
/// calls in millions to the printed two digits, its Discards exactly.
fn readme_prints_the_plant_counts(plant: &[[usize; 4]]) {
    let [cs, me] = plant else { panic!("the plant offers CS and ME: {plant:?}") };
    // "0.41 M OK, 310 Discard, 0.80 M Error": OK and Error in millions, the rare ones counted
    let text = |c: &[usize; 4]| {
        let mut parts = vec![format!("{:.2} M OK", c[0] as f64 / 1e6)];
        parts.extend(
            [(c[1], "Warning"), (c[2], "Discard")].iter().filter(|(n, _)| *n > 0).map(|(n, w)| format!("{n} {w}")),
        );
        parts.push(format!("{:.2} M Error", c[3] as f64 / 1e6));
        parts.join(", ")
    };
    let total: usize = cs.iter().chain(me.iter()).sum();
    let expected = [
        format!(
            "150,000 seeded sequences per interface over all 44 functions with hostile arguments, {:.1} million",
            total as f64 / 1e6
        ),
        format!("calls for the plant (CS: {}; ME: {})", text(cs), text(me)),
        format!(
            "150,000 sequences over all 44 functions per FMU and interface, about {:.1} million calls",
            cs.iter().sum::<usize>() as f64 / 1e6
        ),
    ];
    // docs/testing.md prints the default run's counts, docs/reference.md the sequences a new FMU gets
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let words = |s: &str| s.split_whitespace().collect::<Vec<_>>().join(" ");
    let docs: String = ["docs/testing.md", "docs/reference.md"]
        .iter()
        .map(|d| words(&std::fs::read_to_string(root.join(d)).unwrap_or_else(|e| panic!("{d}: {e}"))))
        .collect::<Vec<_>>()
        .join(" ");
    for e in expected {
        assert!(
            docs.contains(&words(&e)),
            "docs/testing.md or docs/reference.md no longer prints {e:?}: these are the counts now"
        );
    }
}
