//! The simulator and scope are not built yet. Rather than pretend, this
//! binary says so and points at what works today.

use std::process::ExitCode;

fn main() -> ExitCode {
    eprintln!(
        "host-sim: the simulator is not implemented yet.\n\
         What runs today is the designer, e.g.:\n  \
         cargo run --release -p twoport-design -- design impedance"
    );
    ExitCode::from(2)
}
