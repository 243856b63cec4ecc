//! `flatcut ports` lists serial ports; `flatcut devices` lists device profiles with a line each:
//! name, language (HP-GL, GP-GL, G-code) and description.

use crate::Error;

pub fn ports() -> Result<(), Error> {
    let ports = crate::device::serial::list_ports();
    if ports.is_empty() {
        println!("no serial ports found (a USB cutter shows up as /dev/ttyUSB* or /dev/ttyACM* when plugged in)");
    }
    for (path, what) in ports {
        println!("{path}\t{what}");
    }
    Ok(())
}

pub fn devices() -> Result<(), Error> {
    let all = crate::profile::all()?;
    let w = all.iter().map(|p| p.name.len()).max().unwrap_or(0);
    for p in all {
        println!("{:w$}  {:6}  {}", p.name, p.language.label(), p.description);
    }
    if let Some(d) = crate::profile::user_dir() {
        println!("(your own profiles go in {})", d.display());
    }
    Ok(())
}
