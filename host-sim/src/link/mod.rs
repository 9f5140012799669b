//! The host's side of the link to a board: the transport, the session,
//! its errors and the board's own loop run in this process behind the same
//! [`BoardPort`] (the reference a processor-in-the-loop run holds the
//! firmware to) are `twoport-host`'s, here under the simulator's name.

pub use twoport_host::{
    BoardPort, LinkError, LinkFaults, LocalBoard, LocalDelta, LocalFast, LocalSerialArm,
    SerialBoard, Session, ANSWER_TIMEOUT, HEARTBEAT_EVERY,
};
