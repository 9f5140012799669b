//! Devices emulated on a pseudo-terminal, byte for byte as their protocols
//! speak, with the simulator's plant behind them: a driver opens the
//! emulator's port as it opens the device's.

pub mod haply;
