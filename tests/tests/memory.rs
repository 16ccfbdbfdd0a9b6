//! Memory: 10,000 instantiate/step/free cycles through the C ABI. In a test binary of its
//! own so that no other test allocates in the same process while RSS is measured.

use std::ptr::null_mut;

use nigel_integration_tests::{built_fmu, Fmu, CO_SIMULATION, OK};

fn rss_kib() -> u64 {
    let statm = std::fs::read_to_string("/proc/self/statm").unwrap();
    let pages: u64 = statm.split_whitespace().nth(1).unwrap().parse().unwrap();
    pages * 4
}

#[test]
fn ten_thousand_instantiate_free_cycles_do_not_grow_memory() {
    let fmu = Fmu::load(&built_fmu("nigel_plant").unwrap()).unwrap();
    let cycle = || {
        let (i, _log) = fmu.instantiate("cycle", CO_SIMULATION, fmu.guid());
        let i = i.unwrap();
        i.initialize();
        assert_eq!(i.do_step(0.0, 1e-3), OK);
        let mut state = null_mut();
        assert_eq!(unsafe { (i.f().get_fmu_state.unwrap())(i.c, &mut state) }, OK);
        assert_eq!(unsafe { (i.f().free_fmu_state.unwrap())(i.c, &mut state) }, OK);
    };
    for _ in 0..500 {
        cycle();
    }
    let before = rss_kib();
    for _ in 0..10_000 {
        cycle();
    }
    let after = rss_kib();
    eprintln!("RSS before {before} KiB, after 10,000 cycles {after} KiB");
    assert!(after <= before + 1024, "RSS grew from {before} KiB to {after} KiB");
}
