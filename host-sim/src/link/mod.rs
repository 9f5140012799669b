//! The host's side of the link to a board: the transport, the session and
//! its errors are `twoport-host`'s; here, beside them, the board's own
//! loop run in this process behind the same [`BoardPort`], the reference a
//! processor-in-the-loop run holds the firmware to.

mod local;

pub use local::{LocalBoard, LocalDelta, LocalFast, LocalSerialArm};
pub use twoport_host::{
    BoardPort, LinkError, LinkFaults, SerialBoard, Session, ANSWER_TIMEOUT, HEARTBEAT_EVERY,
};
