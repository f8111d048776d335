//! Machines embedded in the binary, each a machine file in `machines/`.

use kinpost_diag::Diagnostics;

use crate::{Machine, machine_from_toml};

/// A built-in machine: its name and the text of `machines/NAME.toml`.
macro_rules! machine {
    ($name:literal) => {
        ($name, include_str!(concat!("../machines/", $name, ".toml")))
    };
}

/// Name and TOML text of every built-in machine.
pub const MACHINES: &[(&str, &str)] = &[
    machine!("mts1600"),
    machine!("ac-grinder"),
    machine!("htm40100h"),
    machine!("trunnion-ac"),
    machine!("head-head-bc"),
    machine!("table-head-bc"),
];

/// Names of the built-in machines.
pub fn names() -> impl Iterator<Item = &'static str> {
    MACHINES.iter().map(|(n, _)| *n)
}

/// The TOML text of a built-in machine.
pub fn source(name: &str) -> Option<&'static str> {
    MACHINES
        .iter()
        .find(|(n, _)| n.eq_ignore_ascii_case(name))
        .map(|(_, s)| *s)
}

/// Loads a built-in machine.
pub fn load(name: &str) -> Option<Result<Machine, Diagnostics>> {
    source(name).map(|s| machine_from_toml(s, &format!("<built-in {name}>")))
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_builtin_loads() {
        for name in super::names() {
            let m = super::load(name).unwrap().unwrap();
            // The registry name is the machine's own name.
            assert_eq!(m.name, name);
            assert!(!m.description.is_empty(), "{name}: no description");
        }
    }
}
