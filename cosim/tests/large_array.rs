//! Recording every element of large FMI 3.0 array outputs (tests/cfmu/fmi3_counter.c's
//! `big` Float64[100000] = y + j, `bigi` Int32[100000] = n + j, `bigb` Boolean[100000] =
//! (n + j) odd, for j from 0) through `cosim run`: every element of every row right. The
//! time, linear in the elements, is measured by `cargo bench -p nigel-cosim --bench
//! array_recording` (docs/third-party-fmus.md), not here.

mod common;
use common::{build_counter, build_counter_with, counter_xml_with_large_arrays, run_to_csv, work_dir};

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

/// A 64-bit array is read exactly and once per recorded row, not once per element
/// (tests/cfmu/fmi3_counter.c built with BIG = 1000: `bigw` Int64[1000] = 2^62 + 1 + n + j,
/// none of them an f64; `bigw_reads` counts the fmi3GetInt64 calls that asked for it).
/// Each row reads the array twice: once for the view's nearest f64s (the values every
/// output has, which connections and the table read) and once for the integers written to
/// the CSV; before, the second read was one per element (1 + 1000 reads per row).
#[test]
fn a_64_bit_array_is_read_once_per_row_and_recorded_exactly() {
    const BIG: usize = 1000;
    let dir = work_dir("large-int64-array");
    let xml = counter_xml_with_large_arrays(BIG, &["bigw"]);
    let Some(fmu) = build_counter_with(&dir, "bigw", &xml, &[&format!("BIG={BIG}")]) else { return };
    let csv = dir.join("out.csv");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_cosim"))
        .arg("run")
        .arg(&fmu)
        .args(["--stop-time", "0.003", "--step", "0.001", "--record", "n", "--record", "bigw_reads"])
        .args(["--record", "bigw", "--output"])
        .arg(&csv)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    // the CSV's text itself: its integers are no f64s
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').map(|h| h.trim_matches('"')).collect();
    assert_eq!(header.len(), 3 + BIG, "time, n, bigw_reads and the elements");
    assert_eq!((header[1], header[2], header[3], header[2 + BIG]), ("n", "bigw_reads", "bigw[1]", "bigw[1000]"));
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 4, "0 .. 3 ms in steps of 1 ms");
    let reads: Vec<i64> = rows.iter().map(|r| r[2].parse().unwrap()).collect();
    for (row, v) in rows.iter().enumerate() {
        let n: i128 = v[1].parse().unwrap();
        for j in 0..BIG {
            let by_hand = (1i128 << 62) + 1 + n + j as i128;
            assert_eq!(v[3 + j], by_hand.to_string(), "row {row}, bigw[{}]", j + 1);
        }
    }
    // the counter is read among the row's values, before the row's exact read: from one
    // row to the next it grows by the reads of one row
    for (row, pair) in reads.windows(2).enumerate() {
        assert_eq!(pair[1] - pair[0], 2, "fmi3GetInt64 calls of bigw between rows {row} and {}: {reads:?}", row + 1);
    }
}
