//! Packages the `own_controller` FMU (`target/fmu/own_controller.fmu`, and its FMI 3.0
//! archive `target/fmu/fmi3/own_controller.fmu` from the same declaration) and writes the
//! closed-loop SSP with it in place of `nigel_controller`
//! (`target/ssp/own_controller_closed_loop.ssp`, from `target/ssp/nigel_closed_loop.ssp`,
//! which `cargo run --release -p build-fmu` writes). The SSP's connections are kept; the
//! controller component's parameter binding (`controller`, a parameter of ours only) is dropped.

use std::io::{Cursor, Read, Write};
use std::path::Path;

use build_fmu::{target_dir, FmuTarget};
use own_controller::OwnController;

const EQUATIONS: &str = "<p>Sampled every 1 ms, outputs held: <code>delta_i = delta_ff_i + s_i k_yaw_rate \
     (yaw_rate_ref - yaw_rate)</code>, <code>s_i</code> = +1 front, -1 rear, clamped to +-delta_max; \
     <code>F = kp_speed (speed_ref - speed)</code> clamped to +-force_max, <code>tau_i = F r_wheel / 4</code>. \
     The pose inputs are not read.</p>";

const OURS: &str = "resources/nigel_controller.fmu";
const OWN: &str = "resources/own_controller.fmu";

/// The closed-loop SSP `closed_loop` with the FMU `own` in place of `nigel_controller`.
fn replace_controller(closed_loop: &[u8], own: &[u8]) -> Result<Vec<u8>, String> {
    let mut input = zip::ZipArchive::new(Cursor::new(closed_loop)).map_err(|e| e.to_string())?;
    let mut out = zip::ZipWriter::new(Cursor::new(Vec::new()));
    let options = zip::write::SimpleFileOptions::default();
    for i in 0..input.len() {
        let mut entry = input.by_index(i).map_err(|e| e.to_string())?;
        let name = entry.name().to_string();
        let mut bytes = Vec::new();
        entry.read_to_end(&mut bytes).map_err(|e| format!("{name}: {e}"))?;
        let (name, bytes) = match name.as_str() {
            OURS => (OWN.to_string(), own.to_vec()),
            "SystemStructure.ssd" => {
                let ssd = String::from_utf8(bytes).map_err(|e| format!("{name}: {e}"))?;
                (name, own_component(&ssd)?.into_bytes())
            }
            _ => (name, bytes),
        };
        out.start_file(name, options).map_err(|e| e.to_string())?;
        out.write_all(&bytes).map_err(|e| e.to_string())?;
    }
    Ok(out.finish().map_err(|e| e.to_string())?.into_inner())
}

/// The SSD with the controller component's source replaced and its parameter bindings dropped.
fn own_component(ssd: &str) -> Result<String, String> {
    let source = format!("source=\"{OURS}\"");
    let start = ssd.find(&source).ok_or_else(|| format!("SystemStructure.ssd: no component with {source}"))?;
    let end = start + ssd[start..].find("</ssd:Component>").ok_or("SystemStructure.ssd: unterminated component")?;
    let mut component = ssd[start..end].replace(&source, &format!("source=\"{OWN}\""));
    if let (Some(a), Some(b)) = (component.find("<ssd:ParameterBindings>"), component.find("</ssd:ParameterBindings>"))
    {
        component.replace_range(a..b + "</ssd:ParameterBindings>".len(), "");
    }
    Ok(format!("{}{}{}", &ssd[..start], component, &ssd[end..]))
}

fn run() -> Result<(), String> {
    let target = FmuTarget::of::<OwnController>("own-controller", EQUATIONS);
    let dir = target_dir();
    let archives = build_fmu::build_for_this_machine(&target, &dir.join("fmu")).map_err(|e| e.to_string())?;
    let fmu = archives[0].0.clone();
    for (path, _) in &archives {
        println!("{}", path.display());
    }
    let closed_loop = dir.join("ssp").join("nigel_closed_loop.ssp");
    let read = |p: &Path| {
        std::fs::read(p).map_err(|e| format!("{}: {e} (run `cargo run --release -p build-fmu`)", p.display()))
    };
    let ssp = replace_controller(&read(&closed_loop)?, &read(&fmu)?)?;
    let path = dir.join("ssp").join("own_controller_closed_loop.ssp");
    std::fs::write(&path, ssp).map_err(|e| format!("{}: {e}", path.display()))?;
    println!("{}", path.display());
    Ok(())
}

fn main() {
    if let Err(e) = run() {
        eprintln!("own-controller: {e}");
        std::process::exit(1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_controller_component_gets_the_own_fmu_and_loses_only_its_parameter_binding() {
        let ssd = "<a><ssd:Component name=\"plant\" source=\"resources/nigel_plant.fmu\"><ssd:ParameterBindings>p\
                   </ssd:ParameterBindings></ssd:Component><ssd:Component name=\"controller\" \
                   source=\"resources/nigel_controller.fmu\"><c/><ssd:ParameterBindings>k</ssd:ParameterBindings>\
                   </ssd:Component></a>";
        let own = own_component(ssd).unwrap();
        assert_eq!(
            own,
            "<a><ssd:Component name=\"plant\" source=\"resources/nigel_plant.fmu\"><ssd:ParameterBindings>p\
             </ssd:ParameterBindings></ssd:Component><ssd:Component name=\"controller\" \
             source=\"resources/own_controller.fmu\"><c/></ssd:Component></a>"
        );
        assert!(own_component("<a/>").unwrap_err().contains("no component"));
    }
}
