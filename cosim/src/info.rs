//! `cosim info` as a library function ([`describe`]), shared by the command line and the
//! Python package (`nigel_cosim.info`): what an FMU or an SSP declares, as text.

use crate::error::Result;
use crate::{Fmu, ImportOptions, UnpackLimits};
use std::fmt::Write;
use std::path::Path;

/// One line into a `String` (writing to a `String` cannot fail).
macro_rules! w {
    ($o:expr, $($a:tt)*) => {{
        let _ = writeln!($o, $($a)*);
    }};
}

/// Whether `path` names an SSP (`.ssp`, or a bare `.ssd`) by its extension.
pub fn is_ssp(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("ssp") || e.eq_ignore_ascii_case("ssd"))
}

fn info_ssp(out: &mut String, path: &Path, limits: &UnpackLimits) -> Result<()> {
    let ssp = crate::read_ssp(path, &ImportOptions { limits: *limits, isolated: true, ..ImportOptions::default() })?;
    let s = &ssp.system;
    let mut lines = vec![format!(
        "system {} (root system {:?}; {} instances, {} connections)",
        path.display(),
        ssp.root_name,
        s.instances.len(),
        s.connections.len()
    )];
    // the experiment a run applies when no --start-time / --stop-time is given
    let (start, stop) = ssp.default_start_stop;
    let start_text = match start {
        Some(t) => format!("start {} s (DefaultExperiment)", plain(t)),
        None => "start 0 s".to_string(),
    };
    let stop_text = match stop {
        Some(t) => format!("stop {} s (DefaultExperiment)", plain(t)),
        None => format!("stop {} s (start + 1 s)", plain(start.unwrap_or(0.0) + 1.0)),
    };
    lines.push(format!("experiment applied without --start-time/--stop-time: {start_text}, {stop_text}"));
    for i in &s.instances {
        // an FMU unpacked from the .ssp is named by its place in the archive (the
        // temporary copy is gone when this command ends)
        let source = match ssp.path_in_archive(i.fmu.source()) {
            Some(inside) => format!("{} in {}", inside.display(), path.display()),
            None => i.fmu.source().display().to_string(),
        };
        let event_mode = match i.fmu.event_mode() {
            Some(e) if e.used => ", Event Mode used",
            Some(_) => ", no Event Mode",
            None => "",
        };
        lines.push(format!("instance {:<20} {source} ({}{event_mode})", i.name, i.fmu.interface().as_str()));
        for (index, v) in &i.start_values {
            let var = &i.fmu.description().model_variables[*index];
            let unit = var.variable_type.unit().map(|u| format!(" {u}")).unwrap_or_default();
            lines.push(format!("  start {} = {v}{unit}", var.name));
        }
    }
    if !ssp.applied.is_empty() {
        // every value the SSD applies, with its binding, mapping, transformation, unit
        // conversion or the system connector it comes through
        lines.push(format!("values applied, in order, where from ({}):", ssp.applied.len()));
        for a in &ssp.applied {
            lines.push(format!("  {a}"));
        }
    }
    for c in &s.connections {
        let unit = |r: &crate::VariableRef| s.variable(r).variable_type.unit().unwrap_or("-").to_string();
        let mut line =
            format!("connection {} [{}] -> {} [{}]", s.name_of(&c.from), unit(&c.from), s.name_of(&c.to), unit(&c.to));
        if c.gain != 1.0 || c.offset != 0.0 {
            line.push_str(&format!("  (x {} + {}", c.gain, c.offset));
            if let Some((f, o)) = c.linear_transformation {
                if (f, o) != (c.gain, c.offset) {
                    line.push_str(&format!(": unit conversion, then LinearTransformation x {f} + {o}"));
                } else {
                    line.push_str(": LinearTransformation");
                }
            } else {
                line.push_str(": unit conversion");
            }
            line.push(')');
        }
        lines.push(line);
    }
    for n in &ssp.notes {
        lines.push(format!("note: {n}"));
    }
    for l in lines {
        out.push_str(&l);
        out.push('\n');
    }
    Ok(())
}

/// A number as a user writes it (`1e-3`, `0.35`, `inf`).
fn plain(x: f64) -> String {
    if x == f64::INFINITY {
        "inf".into()
    } else if x == f64::NEG_INFINITY {
        "-inf".into()
    } else if x != 0.0 && (x.abs() < 1e-4 || x.abs() >= 1e15) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// `cosim info`'s line of the DefaultExperiment attributes present (`None` if none is).
fn default_experiment_line(d: &model_description::DefaultExperiment) -> Option<String> {
    let parts: Vec<String> = [
        d.start_time.map(|v| format!("start {} s", plain(v))),
        d.stop_time.map(|v| format!("stop {} s", plain(v))),
        d.step_size.map(|v| format!("step {} s", plain(v))),
        d.tolerance.map(|v| format!("tolerance {}", plain(v))),
    ]
    .into_iter()
    .flatten()
    .collect();
    (!parts.is_empty()).then(|| format!("default experiment: {}", parts.join(", ")))
}

/// What `cosim info` prints first of an FMU of either generation.
struct Heading<'a> {
    model_name: &'a str,
    fmi_version: &'a str,
    /// The identifying attribute's name and value (`guid` or `instantiationToken`).
    token: (&'a str, &'a str),
    description: Option<&'a str>,
    interfaces: Vec<String>,
    continuous_states: usize,
    event_indicators: usize,
    default_experiment: Option<&'a model_description::DefaultExperiment>,
}

impl Heading<'_> {
    /// The model line, its description, interfaces, sizes and default experiment.
    fn write(&self, out: &mut String) {
        let (token_name, token) = self.token;
        w!(out, "model {} (FMI {}), {token_name} {token}", self.model_name, self.fmi_version);
        if let Some(d) = self.description.filter(|d| !d.is_empty()) {
            w!(out, "{d}");
        }
        w!(out, "interfaces: {}", self.interfaces.join(", "));
        w!(out, "continuous states: {}, event indicators: {}", self.continuous_states, self.event_indicators);
        if let Some(line) = self.default_experiment.and_then(default_experiment_line) {
            w!(out, "{line}");
        }
    }
}

/// One row of the variables' table: each cell left-aligned in its column's width, then the
/// last (unpadded) cell.
fn table_row(out: &mut String, widths: &[usize], cells: &[&str], last: &str) {
    for (cell, width) in cells.iter().zip(widths) {
        let _ = write!(out, "{cell:<width$} ");
    }
    w!(out, "{last}");
}

/// What `cosim info` prints of the FMU or SSP at `path`: the model, its interfaces and
/// experiment, and one line per variable (an FMU); the instances, the values applied and
/// the connections (an SSP). One line per item, each ending in a newline.
pub fn describe(path: &Path, limits: &UnpackLimits) -> Result<String> {
    let mut out = String::new();
    if is_ssp(path) {
        info_ssp(&mut out, path, limits)?;
        return Ok(out);
    }
    if let Some(md) = crate::load::read_fmi3_description(path, limits)? {
        info_fmi3(&mut out, &md);
        return Ok(out);
    }
    info_fmi2(&mut out, path, limits)?;
    Ok(out)
}

/// [`describe`] of an FMI 2.0 FMU.
fn info_fmi2(out: &mut String, path: &Path, limits: &UnpackLimits) -> Result<()> {
    use model_description::VariableType;
    let fmu = Fmu::load_with(path, &ImportOptions { limits: *limits, isolated: true, ..ImportOptions::default() })?;
    let md = fmu.description();
    let cs = md.co_simulation.as_ref().map(|c| format!("CoSimulation ({})", c.model_identifier));
    let me = md.model_exchange.as_ref().map(|c| format!("ModelExchange ({})", c.model_identifier));
    Heading {
        model_name: &md.model_name,
        fmi_version: &md.fmi_version,
        token: ("guid", &md.guid),
        description: md.description.as_deref(),
        interfaces: [cs, me].into_iter().flatten().collect(),
        continuous_states: md.states().len(),
        event_indicators: md.number_of_event_indicators as usize,
        default_experiment: md.default_experiment.as_ref(),
    }
    .write(out);
    const WIDTHS: [usize; 7] = [24, 19, 11, 8, 8, 12, 18];
    table_row(
        out,
        &WIDTHS,
        &["name", "causality", "variability", "type", "unit", "start", "min .. max"],
        "description",
    );
    for v in &md.model_variables {
        let range = |min: Option<String>, max: Option<String>| match (min, max) {
            (None, None) => String::new(),
            (a, b) => format!("{} .. {}", a.unwrap_or_default(), b.unwrap_or_default()),
        };
        let (start, bounds) = match &v.variable_type {
            VariableType::Real { start, min, max, .. } => (start.map(plain), range(min.map(plain), max.map(plain))),
            VariableType::Integer { start, min, max } => {
                (start.map(|x| x.to_string()), range(min.map(|x| x.to_string()), max.map(|x| x.to_string())))
            }
            VariableType::Enumeration { start, declared_type, min, max } => (
                start.map(|x| {
                    let item = md.type_definitions.iter().find(|t| &t.name == declared_type).and_then(|t| t.item(x));
                    match item {
                        Some(item) => format!("{x} ({})", item.name),
                        None => x.to_string(),
                    }
                }),
                range(min.map(|x| x.to_string()), max.map(|x| x.to_string())),
            ),
            VariableType::Boolean { start } => (start.map(|x| x.to_string()), String::new()),
            VariableType::String { start } => (start.as_ref().map(|x| format!("{x:?}")), String::new()),
        };
        let start = start.unwrap_or_else(|| "-".into());
        let cells = [
            v.name.as_str(),
            v.causality.as_str(),
            v.variability.as_str(),
            v.variable_type.type_name(),
            v.variable_type.unit().unwrap_or("-"),
            &start,
            &bounds,
        ];
        table_row(out, &WIDTHS, &cells, v.description.as_deref().unwrap_or(""));
    }
    Ok(())
}

/// `cosim info` of an FMI 3.0 FMU's clocks (kind, causality, interval, shift, what each
/// governs).
fn info_clocks(out: &mut String, md: &model_description::fmi3::ModelDescription) {
    let clocks = crate::clocks::clocks_of(md);
    if clocks.is_empty() {
        return;
    }
    w!(out, "clocks:");
    for c in &clocks {
        let interval = match c.interval {
            Some(i) => format!("interval {} s, shift {} s", plain(i), plain(c.shift)),
            None if c.kind.is_time_based() => "interval from the FMU".to_string(),
            None => "no interval".to_string(),
        };
        let governs = if c.governs.is_empty() { String::new() } else { format!("; governs {}", c.governs.join(", ")) };
        let line = format!("  {:<24} {:<6} {:<9} {interval}{governs}", c.name, c.causality.as_str(), c.kind.as_str());
        w!(out, "{}", line.trim_end());
    }
}

/// `cosim info` of an FMI 3.0 Co-Simulation FMU's Event Mode: whether a run uses it by
/// default and why, and what `--event-mode on` and `off` would do.
fn info_event_mode(out: &mut String, md: &model_description::fmi3::ModelDescription) {
    use crate::EventModeChoice;
    let clocks = crate::clocks::clocks_of(md);
    let said = |choice| match crate::event_mode::decide(md, &clocks, choice) {
        Ok(e) if e.used => format!("used: {}", e.why),
        Ok(e) => format!("not used: {}", e.why),
        Err(reason) => format!("refused: {reason}"),
    };
    w!(out, "Co-Simulation Event Mode (eventModeUsed): {}", said(EventModeChoice::Auto));
    for choice in [EventModeChoice::On, EventModeChoice::Off] {
        w!(out, "  with --event-mode {}: {}", choice.as_str(), said(choice));
    }
}

/// `cosim info` of an FMI 3.0 FMU: interface types with their capabilities, and every
/// variable with its type and dimensions.
fn info_fmi3(out: &mut String, md: &model_description::fmi3::ModelDescription) {
    use model_description::fmi3::{Bound, Dimension, Values};
    let flags = |pairs: &[(bool, &str)]| -> String {
        let v: Vec<&str> = pairs.iter().filter(|(on, _)| *on).map(|(_, n)| *n).collect();
        if v.is_empty() {
            String::new()
        } else {
            format!("; {}", v.join(", "))
        }
    };
    // an interface element, its own capabilities and then those every interface may have
    let interface = |element: &str, common: &model_description::fmi3::InterfaceCommon, own: &[(bool, &str)]| {
        let mut pairs = own.to_vec();
        pairs.push((common.can_get_and_set_fmu_state, "FMU state"));
        pairs.push((common.provides_directional_derivatives, "directional derivatives"));
        format!("{element} ({}{})", common.model_identifier, flags(&pairs))
    };
    let mut interfaces = Vec::new();
    if let Some(cs) = &md.co_simulation {
        let own = [
            (cs.can_handle_variable_communication_step_size, "variable step"),
            (cs.might_return_early_from_do_step, "early return"),
            (cs.has_event_mode, "event mode"),
        ];
        interfaces.push(interface("CoSimulation", &cs.common, &own));
    }
    if let Some(me) = &md.model_exchange {
        interfaces.push(interface(
            "ModelExchange",
            &me.common,
            &[(me.needs_completed_integrator_step, "completed integrator step")],
        ));
    }
    if let Some(se) = &md.scheduled_execution {
        interfaces.push(format!("ScheduledExecution ({}; not run by cosim)", se.common.model_identifier));
    }
    Heading {
        model_name: &md.model_name,
        fmi_version: &md.fmi_version,
        token: ("instantiationToken", &md.instantiation_token),
        description: md.description.as_deref(),
        interfaces,
        continuous_states: md.model_structure.continuous_state_derivatives.len(),
        event_indicators: md.model_structure.event_indicators.len(),
        default_experiment: md.default_experiment.as_ref(),
    }
    .write(out);
    if md.co_simulation.is_some() {
        info_event_mode(out, md);
    }
    const WIDTHS: [usize; 8] = [24, 19, 11, 11, 10, 8, 12, 18];
    let heading = ["name", "causality", "variability", "type", "dimensions", "unit", "start", "min .. max"];
    table_row(out, &WIDTHS, &heading, "description");
    for v in &md.model_variables {
        let dims = if v.dimensions.is_empty() {
            "-".to_string()
        } else {
            let each: Vec<String> = v
                .dimensions
                .iter()
                .map(|d| match d {
                    Dimension::Fixed(n) => n.to_string(),
                    Dimension::Variable(vr) => md.variable(*vr).map_or_else(|| format!("vr {vr}"), |s| s.name.clone()),
                })
                .collect();
            format!("[{}]", each.join(","))
        };
        let start = v.start.as_ref().map(|s| {
            let items: Vec<String> = match s {
                Values::Float(x) => x.iter().map(|x| plain(*x)).collect(),
                Values::Int(x) => x.iter().map(|x| x.to_string()).collect(),
                Values::Boolean(x) => x.iter().map(|x| x.to_string()).collect(),
                Values::String(x) => x.iter().map(|x| format!("{x:?}")).collect(),
                // binary start values as their size (the results record binary values as hex)
                Values::Binary(x) => x.iter().map(|x| format!("{} bytes", x.len())).collect(),
            };
            if items.len() == 1 {
                items[0].clone()
            } else {
                format!("[{}]", items.join(" "))
            }
        });
        let bound = |b: Option<Bound>| match b {
            Some(Bound::Float(x)) => plain(x),
            Some(Bound::Int(i)) => i.to_string(),
            None => String::new(),
        };
        let range = if v.min.is_none() && v.max.is_none() {
            String::new()
        } else {
            format!("{} .. {}", bound(v.min), bound(v.max))
        };
        // one row per name: the variable's, then each <Alias>'s (recorded under its own name
        // too, the same value as its variable's)
        let mut row = |name: &str, start: &str, range: &str, what: &str| {
            let cells = [
                name,
                v.causality.as_str(),
                v.variability.as_str(),
                v.value_type.element(),
                &dims,
                md.unit_of(v).unwrap_or("-"),
                start,
                range,
            ];
            table_row(out, &WIDTHS, &cells, what);
        };
        row(&v.name, start.as_deref().unwrap_or("-"), &range, v.description.as_deref().unwrap_or(""));
        for a in &v.aliases {
            let display_unit = a
                .display_unit
                .as_ref()
                .map(|u| format!(" (display unit {u}; recorded in the variable's unit)"))
                .unwrap_or_default();
            let description = a.description.as_ref().map(|d| format!(": {d}")).unwrap_or_default();
            row(&a.name, "-", "", &format!("alias of {}{display_unit}{description}", v.name));
        }
    }
    info_clocks(out, md);
    // what FMI 3.0 adds beyond variables, one line each: structural parameters here
    // (Configuration Mode), then model partitions (Scheduled Execution)
    for p in crate::structural::structural_parameters(md) {
        let sizes = if p.sizes.is_empty() { String::new() } else { format!(", sizes {}", p.sizes.join(", ")) };
        w!(
            out,
            "structural parameter {} ({}, start {}{sizes}): set with --set {}=VALUE, in Configuration Mode",
            p.name,
            p.variability,
            p.start.as_deref().unwrap_or("-"),
            p.name
        );
    }
    match crate::partitions::model_partitions(md) {
        Ok(partitions) if md.scheduled_execution.is_some() => {
            for p in partitions {
                w!(
                    out,
                    "model partition {} (clock, priority {}): ticks {}; run with --interface se",
                    p.name,
                    p.priority,
                    p.ticks_text()
                );
            }
        }
        Err(reason) if md.scheduled_execution.is_some() => w!(out, "model partitions: {reason}"),
        _ => {}
    }
    // clocks are run (listed above), not left out
    let left_out: Vec<_> =
        crate::fmi3::not_in_view(md).into_iter().filter(|(_, why)| *why != crate::fmi3::LeftOut::Clock).collect();
    if !left_out.is_empty() {
        let each: Vec<String> = left_out.iter().map(|(name, why)| format!("{name} ({})", why.as_str())).collect();
        w!(out, "not run by cosim (neither recorded, set nor connected): {}", each.join(", "));
    }
}
