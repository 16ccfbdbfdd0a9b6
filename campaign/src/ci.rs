//! A campaign's runs as a CI test report (`campaign run --junit`, `--summary-md`): one
//! test case per run, named by its number and varied values; a run that failed a check or
//! ended early is a failure, one that could not complete (failed, panicked, crashed, timed
//! out) an error, each with its status and message.

use nigel_cosim::junit::{TestCase, TestSuite};

use crate::results::{status_name, Row, STATUS_CHECK_FAILED, STATUS_ENDED, STATUS_OK};
use crate::spec::Spec;

/// The case name of a run: `run 7 (mu = 0.4, controller = robust)`.
pub fn case_name(spec: &Spec, row: &Row) -> String {
    let values: Vec<String> = spec
        .columns
        .iter()
        .zip(&row.values)
        .map(|(c, v)| {
            let case = c.case_names();
            match case.get(*v as usize).filter(|_| v.fract() == 0.0 && *v >= 0.0) {
                Some(name) => format!("{} = {name}", c.name),
                None => format!("{} = {v}", c.name),
            }
        })
        .collect();
    if values.is_empty() {
        format!("run {}", row.run)
    } else {
        format!("run {} ({})", row.run, values.join(", "))
    }
}

/// The suite of a campaign's rows (`seconds`: the invocation's wall time).
pub fn suite(spec: &Spec, rows: &[Row], seconds: f64) -> TestSuite {
    let stem = spec.path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    let classname = format!("campaign.{stem}");
    let cases = rows
        .iter()
        .map(|r| {
            let name = case_name(spec, r);
            let message = format!("{}: {}", status_name(r.status), r.message);
            let mut case = match r.status {
                STATUS_OK => TestCase::passed(&classname, &name),
                STATUS_CHECK_FAILED | STATUS_ENDED => TestCase::failed(&classname, &name, &message),
                _ => TestCase::error(&classname, &name, &message),
            };
            let metrics: Vec<String> = spec
                .metrics
                .iter()
                .zip(&r.values[spec.columns.len()..])
                .map(|((n, _), v)| format!("{n} = {v}"))
                .collect();
            if !metrics.is_empty() {
                case.output = Some(metrics.join(", "));
            }
            case
        })
        .collect();
    TestSuite { name: format!("campaign {}", spec.path.display()), time: seconds, cases }
}
