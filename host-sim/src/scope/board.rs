//! The scope's link to a board of any number of axes: lockstep (this
//! simulation is its plant) or free running (it runs on its own sensors and
//! the scope watches), and what the board last said.

use crate::engine::scene::Scene;
use crate::link::{BoardPort, LinkFaults, SerialBoard, Session};
use crate::pil::Lockstep;
use crate::Error;
use crate::{Sample, Simulation};
use twoport_link::{GainsReply, Message, Status, Telemetry};

/// A connected board.
pub struct BoardLink {
    session: Session<Box<dyn BoardPort>>,
    /// What it is connected through (a port path, or "in-process").
    pub port: String,
    /// Lockstep: this simulation is the board's plant (processor in the
    /// loop, the QEMU image). Otherwise the board runs on its own sensors
    /// and clock and the scope only watches and talks to it.
    pub lockstep: bool,
    /// The last telemetry.
    pub telemetry: Option<Telemetry>,
    /// The board's last answer to a gain request.
    pub reply: Option<String>,
    /// Latched faults the board reported.
    pub faults: Option<u16>,
    /// The board's state machine, as it last said.
    pub status: Option<Status>,
    /// Its last refusal of a mode change.
    pub refusal: Option<String>,
    /// The device the PC drives, by name, where it is one
    /// ([`WithBoard::connect_device`]).
    pub device: Option<String>,
}

impl BoardLink {
    /// Connect to the board at the other end of `port` (named `name`) for
    /// a device of `axes` axes. In lockstep, `scene`'s device must be the
    /// board's (see [`crate::pil::check_scene`]); the board is asked for
    /// its status at once.
    pub fn connect(
        port: Box<dyn BoardPort>,
        name: &str,
        lockstep: bool,
        scene: &Scene,
    ) -> Result<Self, Error> {
        if lockstep {
            crate::pil::check_scene(scene)?;
        }
        let mut session = Session::open_axes(port, LinkFaults::default(), scene.axes)?;
        session.send(&Message::GetStatus)?;
        Ok(BoardLink {
            session,
            port: name.to_string(),
            lockstep,
            telemetry: None,
            reply: None,
            faults: None,
            status: None,
            refusal: None,
            device: None,
        })
    }

    /// One lockstep tick of `sim` with the board as its controller.
    pub fn step<const N: usize>(&mut self, sim: &mut Simulation<N>) -> Result<Sample<N>, Error> {
        self.session.step(sim).map(|(s, _)| s)
    }

    /// A free-running board: keep its link watchdog fed and read what it
    /// sent.
    pub fn watch(&mut self) -> Result<(), Error> {
        self.session.send(&Message::Heartbeat)?;
        Ok(self.session.poll()?)
    }

    /// Say `msg` to the board (a mode change, a fault clear, new gains);
    /// its answer comes back as a status, a reply or a refusal.
    pub fn tell(&mut self, msg: &Message) -> Result<(), Error> {
        Ok(self.session.send(msg)?)
    }

    /// Disarm the board and let it go.
    pub fn disconnect(mut self) {
        let _ = self.session.send(&Message::Disarm);
    }

    /// Take what the board has sent: its statuses, replies and refusals
    /// are kept here; its telemetry is returned, oldest first, for the
    /// plots.
    pub fn take_telemetry(&mut self) -> Vec<Telemetry> {
        let mut telemetry = Vec::new();
        for m in self.session.take_messages() {
            match m {
                Message::Telemetry(t) => {
                    self.telemetry = Some(t);
                    telemetry.push(t);
                }
                Message::GainsReply(GainsReply::Accepted(_)) => {
                    self.reply = Some("accepted".into());
                }
                Message::GainsReply(GainsReply::Refused(r)) => {
                    self.reply = Some(format!("refused on axis {}: {:?}", r.axis, r.why));
                }
                Message::FaultReport { faults, .. } => self.faults = Some(faults),
                Message::Status(st) => {
                    self.faults = (st.faults != 0).then_some(st.faults);
                    self.status = Some(st);
                    self.refusal = None;
                }
                Message::ModeRefused { asked, why } => {
                    self.refusal = Some(format!("{asked:?} refused: {why:?}"));
                }
                _ => {}
            }
        }
        telemetry
    }
}

/// A scope state that can hold a board: the link, where its problems are
/// said, and the scene whose device a lockstep board must be. Connecting,
/// leaving and talking to the board are written once, here.
pub trait WithBoard {
    /// The link, the state's message line, and its scene.
    fn board_parts(&mut self) -> (&mut Option<BoardLink>, &mut Option<String>, &Scene);

    /// Board mode: connect to the board at the serial `port`; with
    /// `lockstep` the simulation is its plant (processor in the loop),
    /// without it the board runs on its own sensors and the scope watches.
    fn connect(&mut self, port: &str, lockstep: bool) {
        match SerialBoard::open(port) {
            Ok(p) => self.connect_port(Box::new(p), port, lockstep),
            Err(e) => *self.board_parts().1 = Some(format!("board at {port}: {e}")),
        }
    }

    /// [`connect`](Self::connect) through any port (a board in-process).
    fn connect_port(&mut self, port: Box<dyn BoardPort>, name: &str, lockstep: bool) {
        let (board, message, scene) = self.board_parts();
        match BoardLink::connect(port, name, lockstep, scene) {
            Ok(b) => {
                *board = Some(b);
                *message = None;
            }
            Err(e) => *message = Some(format!("board at {name}: {e}")),
        }
    }

    /// Board mode on a device the PC drives, by `name` (`twoport
    /// devices`' names) at `path` (a Touch: its Touch Setup name), with
    /// the `file` it needs (a Falcon's firmware, a Touch's HD library): its
    /// image in this computer's loop, free running, the scope watching.
    fn connect_device(&mut self, name: &str, path: &str, file: Option<&std::path::Path>) {
        match twoport_host::attached::open(name, path, file) {
            Ok((pc, _)) => {
                let label = format!("{name} at {path:?}");
                self.connect_port(Box::new(pc), &label, false);
                if let Some(b) = self.board_parts().0.as_mut() {
                    b.device = Some(name.to_string());
                }
            }
            Err(e) => *self.board_parts().1 = Some(format!("{name} at {path:?}: {e}")),
        }
    }

    /// Calibrate a device at its image's rest pose, the handle held there
    /// (a board not a device's: nothing to do, and said so).
    fn calibrate_device(&mut self) {
        let (board, message, _) = self.board_parts();
        let Some(name) = board.as_ref().and_then(|b| b.device.clone()) else {
            *message = Some("not a device the PC drives: calibrate it as its board".into());
            return;
        };
        match twoport_host::attached::rest_pose(&name) {
            Ok(rest) => {
                let pm: Vec<i64> = rest.iter().map(|q| (q * 1e12).round() as i64).collect();
                match twoport_link::Axes::from_slice(&pm) {
                    Some(position_pm) => self.tell_board(Message::Calibrate { position_pm }),
                    None => *message = Some(format!("{name}: {} axes", pm.len())),
                }
            }
            Err(e) => *message = Some(e.to_string()),
        }
    }

    /// Leave board mode, disarming the board.
    fn disconnect(&mut self) {
        if let Some(b) = self.board_parts().0.take() {
            b.disconnect();
        }
    }

    /// Say `msg` to the board (a mode change, a fault clear); its answer
    /// comes back as a status or a refusal.
    fn tell_board(&mut self, msg: Message) {
        let (board, message, _) = self.board_parts();
        if let Some(Err(e)) = board.as_mut().map(|b| b.tell(&msg)) {
            *message = Some(format!("board: {e}"));
        }
    }
}

/// What the board panel's connect controls hold.
#[derive(Clone, Debug)]
pub struct BoardChoice {
    /// Serial port path.
    pub port: String,
    /// Lockstep (processor in the loop) or free running.
    pub lockstep: bool,
    /// A device the PC drives, by name (empty: a board on the port).
    pub device: String,
    /// The file that device needs (a Falcon's firmware, a Touch's HD
    /// library; empty: none).
    pub file: String,
}

impl Default for BoardChoice {
    fn default() -> Self {
        BoardChoice {
            port: String::new(),
            lockstep: true,
            device: String::new(),
            file: String::new(),
        }
    }
}
