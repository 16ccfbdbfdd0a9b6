//! Test reports for CI services: JUnit XML (as Jenkins' JUnit plugin, GitLab's unit test
//! reports and the GitHub JUnit reporters read it) and a Markdown table (a CI job summary).
//!
//! The XML: `<testsuites name tests failures errors skipped time>` holding one
//! `<testsuite name tests failures errors skipped time>` per suite, holding one
//! `<testcase classname name [time]>` per case, which holds a `<failure message type>`
//! (the case ran and did not hold), an `<error message type>` (it could not be judged) or
//! a `<skipped message>` with the full text inside, and optionally `<system-out>`. The
//! attributes are those the Ant / Surefire schemas (`junit-4.xsd`, `junit-10.xsd`) name;
//! times are seconds with three decimals.

use std::fmt::Write as _;

/// How a test case ended.
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    /// It held.
    Passed,
    /// It ran and did not hold: a one-line message and the details.
    Failed {
        /// One line.
        message: String,
        /// The full text.
        detail: String,
    },
    /// It could not be judged (the run failed, a file was unreadable).
    Error {
        /// One line.
        message: String,
        /// The full text.
        detail: String,
    },
}

/// One test case.
#[derive(Clone, Debug, PartialEq)]
pub struct TestCase {
    /// The group (`cosim.check`, `cosim.baseline`, `campaign.robustness`).
    pub classname: String,
    /// The case (the check, the signal, the run).
    pub name: String,
    /// Seconds it took, if known.
    pub time: Option<f64>,
    /// How it ended.
    pub outcome: Outcome,
    /// Text for `<system-out>` (values, figures), if any.
    pub output: Option<String>,
}

impl TestCase {
    /// A case that held.
    pub fn passed(classname: &str, name: &str) -> TestCase {
        TestCase { classname: classname.into(), name: name.into(), time: None, outcome: Outcome::Passed, output: None }
    }

    /// A case that ran and did not hold.
    pub fn failed(classname: &str, name: &str, message: &str) -> TestCase {
        TestCase {
            outcome: Outcome::Failed { message: message.into(), detail: message.into() },
            ..TestCase::passed(classname, name)
        }
    }

    /// A case that could not be judged.
    pub fn error(classname: &str, name: &str, message: &str) -> TestCase {
        TestCase {
            outcome: Outcome::Error { message: message.into(), detail: message.into() },
            ..TestCase::passed(classname, name)
        }
    }
}

/// A suite of cases.
#[derive(Clone, Debug, PartialEq)]
pub struct TestSuite {
    /// Its name (`cosim run closed_loop.ssp`).
    pub name: String,
    /// Seconds it took.
    pub time: f64,
    /// The cases.
    pub cases: Vec<TestCase>,
}

impl TestSuite {
    /// `(tests, failures, errors)`.
    pub fn counts(&self) -> (usize, usize, usize) {
        let f = self.cases.iter().filter(|c| matches!(c.outcome, Outcome::Failed { .. })).count();
        let e = self.cases.iter().filter(|c| matches!(c.outcome, Outcome::Error { .. })).count();
        (self.cases.len(), f, e)
    }
}

/// `text` escaped for XML 1.0 attributes and text: `& < > " '` as entities (quick-xml's
/// `escape`), the control characters XML 1.0 does not allow as `?`.
pub fn escape(text: &str) -> String {
    let allowed = |c: char| matches!(c, '\t' | '\n' | '\r') || (c as u32 >= 0x20 && c != '\u{FFFE}' && c != '\u{FFFF}');
    let text: String = text.chars().map(|c| if allowed(c) { c } else { '?' }).collect();
    quick_xml::escape::escape(text).into_owned()
}

/// A one-line message: the first line, at most 500 characters.
fn one_line(message: &str) -> String {
    let first = message.lines().next().unwrap_or("");
    let mut s: String = first.chars().take(500).collect();
    if s.len() < first.len() {
        s.push_str("...");
    }
    s
}

/// Seconds with three decimals (the Surefire schema's time pattern).
fn seconds(t: f64) -> String {
    format!("{:.3}", if t.is_finite() && t > 0.0 { t } else { 0.0 })
}

/// The JUnit XML document of `suites` under `<testsuites name=...>`.
pub fn xml(name: &str, suites: &[TestSuite]) -> String {
    let (mut tests, mut failures, mut errors, mut time) = (0, 0, 0, 0.0);
    for s in suites {
        let (t, f, e) = s.counts();
        tests += t;
        failures += f;
        errors += e;
        time += s.time;
    }
    let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        x,
        "<testsuites name=\"{}\" tests=\"{tests}\" failures=\"{failures}\" errors=\"{errors}\" skipped=\"0\" time=\"{}\">",
        escape(name),
        seconds(time)
    );
    for s in suites {
        let (t, f, e) = s.counts();
        let _ = writeln!(
            x,
            "  <testsuite name=\"{}\" tests=\"{t}\" failures=\"{f}\" errors=\"{e}\" skipped=\"0\" time=\"{}\">",
            escape(&s.name),
            seconds(s.time)
        );
        for c in &s.cases {
            let time = c.time.map(|t| format!(" time=\"{}\"", seconds(t))).unwrap_or_default();
            let _ =
                write!(x, "    <testcase classname=\"{}\" name=\"{}\"{time}", escape(&c.classname), escape(&c.name));
            let body = match &c.outcome {
                Outcome::Passed => None,
                Outcome::Failed { message, detail } => Some(("failure", "failure", message, detail)),
                Outcome::Error { message, detail } => Some(("error", "error", message, detail)),
            };
            if body.is_none() && c.output.is_none() {
                x.push_str("/>\n");
                continue;
            }
            x.push_str(">\n");
            if let Some((tag, kind, message, detail)) = body {
                let _ = writeln!(
                    x,
                    "      <{tag} message=\"{}\" type=\"{kind}\">{}</{tag}>",
                    escape(&one_line(message)),
                    escape(detail)
                );
            }
            if let Some(o) = &c.output {
                let _ = writeln!(x, "      <system-out>{}</system-out>", escape(o));
            }
            x.push_str("    </testcase>\n");
        }
        x.push_str("  </testsuite>\n");
    }
    x.push_str("</testsuites>\n");
    x
}

/// A Markdown summary of `suites` for a CI job summary (`$GITHUB_STEP_SUMMARY`): a heading,
/// the counts, and a table of the cases with their verdicts.
pub fn markdown(title: &str, suites: &[TestSuite]) -> String {
    let cell = |s: &str| one_line(s).replace('|', "\\|");
    let mut md = format!("## {}\n\n", cell(title));
    for s in suites {
        let (t, f, e) = s.counts();
        let verdict = if f + e == 0 { "passed" } else { "FAILED" };
        let _ = writeln!(md, "**{}**: {verdict} ({t} tests, {f} failed, {e} errors)\n", cell(&s.name));
        md.push_str("| test | result | detail |\n|---|---|---|\n");
        for c in &s.cases {
            let (result, detail) = match &c.outcome {
                Outcome::Passed => ("pass", c.output.as_deref().unwrap_or("")),
                Outcome::Failed { message, .. } => ("**FAIL**", message.as_str()),
                Outcome::Error { message, .. } => ("**ERROR**", message.as_str()),
            };
            let _ = writeln!(md, "| {} | {result} | {} |", cell(&format!("{} {}", c.classname, c.name)), cell(detail));
        }
        md.push('\n');
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_document_counts_and_escapes() {
        let mut failed =
            TestCase::failed("cosim.check", "max(abs(y)) < 0.6", "max(abs(y)) < 0.6 fails: 0.7 < 0.6 is false");
        failed.time = Some(0.0123);
        let suite = TestSuite {
            name: "cosim run a&b.ssp".into(),
            time: 1.5,
            cases: vec![
                TestCase::passed("cosim.check", "final(x) > 1"),
                failed,
                TestCase::error("cosim.baseline", "plant.y", "missing in the result\u{1}"),
            ],
        };
        let x = xml("cosim", std::slice::from_ref(&suite));
        assert!(x.contains(
            "<testsuites name=\"cosim\" tests=\"3\" failures=\"1\" errors=\"1\" skipped=\"0\" time=\"1.500\">"
        ));
        assert!(x.contains("<testsuite name=\"cosim run a&amp;b.ssp\" tests=\"3\" failures=\"1\" errors=\"1\""));
        assert!(x.contains("<testcase classname=\"cosim.check\" name=\"final(x) &gt; 1\"/>"));
        assert!(x.contains("name=\"max(abs(y)) &lt; 0.6\" time=\"0.012\">"));
        assert!(x.contains("<error message=\"missing in the result?\" type=\"error\">missing in the result?</error>"));
        let md = markdown("cosim run", &[suite]);
        assert!(md.contains("**cosim run a&b.ssp**: FAILED (3 tests, 1 failed, 1 errors)"), "{md}");
        assert!(
            md.contains("| cosim.check max(abs(y)) < 0.6 | **FAIL** | max(abs(y)) < 0.6 fails: 0.7 < 0.6 is false |")
        );
    }
}
