//! Recording every element of large FMI 3.0 array outputs (tests/cfmu/fmi3_counter.c's
//! `big` Float64[100000] = y + j, `bigi` Int32[100000] = n + j, `bigb` Boolean[100000] =
//! (n + j) odd, for j from 0) through `cosim run`: every element of every row right. The
//! time, linear in the elements, is measured by `cargo bench -p nigel-cosim --bench
//! array_recording` (docs/third-party-fmus.md), not here.

mod common;
use common::{build_counter, counter_xml_with_large_arrays, run_to_csv, work_dir};

#[test]
fn every_element_of_100000_element_arrays_is_recorded() {
    let dir = work_dir("large-array");
    let Some(fmu) = build_counter(&dir, "big", &counter_xml_with_large_arrays(100_000, &["big", "bigi", "bigb"]))
    else {
        return;
    };
    let csv = dir.join("out.csv");
    let (header, rows) = run_to_csv(
        std::process::Command::new(env!("CARGO_BIN_EXE_cosim"))
            .arg("run")
            .arg(&fmu)
            .args(["--stop-time", "0.002", "--step", "0.001", "--record", "y", "--record", "n"])
            .args(["--record", "big", "--record", "bigi", "--record", "bigb", "--output"])
            .arg(&csv),
        &csv,
    );
    assert_eq!(header.len(), 3 + 3 * 100_000, "time, y, n and the elements");
    for (first, name) in [(3, "big"), (100_003, "bigi"), (200_003, "bigb")] {
        assert_eq!(header[first], format!("{name}[1]"));
        assert_eq!(header[first + 99_999], format!("{name}[100000]"));
    }
    assert_eq!(rows.len(), 3, "0 .. 2 ms in steps of 1 ms");
    for (row, v) in rows.iter().enumerate() {
        let (y, n) = (v[1], v[2]);
        // the FMU computes big[j] = y + j in double: the same sum here, bit for bit (the
        // CSV holds shortest round-trip decimals); n + j and the parity are integers
        for j in 0..100_000usize {
            assert_eq!(v[3 + j], y + j as f64, "row {row}, big[{}]", j + 1);
            assert_eq!(v[100_003 + j], n + j as f64, "row {row}, bigi[{}]", j + 1);
            assert_eq!(v[200_003 + j], ((n as usize + j) % 2) as f64, "row {row}, bigb[{}]", j + 1);
        }
    }
}
