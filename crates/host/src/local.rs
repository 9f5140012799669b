//! The Excalibur board images' loop in this process, behind the same
//! [`BoardPort`] as a serial board: the reference a processor-in-the-loop
//! run holds the firmware to, bit for bit.

use crate::in_process::ByteQueues;
use crate::{BoardPort, LinkError};
use std::time::Duration;
use twoport_board::excalibur::{self, fast, xyz, REGION_POINTS};
use twoport_board::linkage::{self as linkage_image, DeltaBoard, SerialArmBoard};
use twoport_board::Board;
use twoport_config::{RamFlash, Store};
use twoport_control::drive::Drive;
use twoport_control::kinematics::{Delta, SerialArm};
use twoport_control::passivity::SeriesDamper;
use twoport_control::servo::Servo;
use twoport_control::ve::UnilateralWall;

/// A board image's loop, in this process: the Excalibur's plain image,
/// its passivity image (`D` with the series damper), its three-axis image
/// (`N` = 3), or a linkage image (`D`, the linkage's servo, with a region
/// of `R` points).
pub struct LocalBoard<D = Servo<UnilateralWall>, const N: usize = 1, const R: usize = REGION_POINTS>
{
    board: Board<D, R, N>,
    link: ByteQueues,
    /// Its stored configuration, in RAM as on the QEMU images.
    store: Store<RamFlash<512, 256>>,
}

impl<D: Drive<N>, const N: usize, const R: usize> LocalBoard<D, N, R> {
    /// `board`, driven by the link's sensor frames.
    fn driven(board: Board<D, R, N>) -> Self {
        let mut board = board.with_pil(true);
        // As the QEMU images boot: the configuration from a RAM flash.
        let mut store = Store::new(RamFlash::<512, 256>::new(), 0, 256);
        board.boot_config(&mut store);
        LocalBoard {
            board,
            link: ByteQueues::default(),
            store,
        }
    }

    /// The same board with each axis homing with its `cfg` (e.g. on an
    /// encoder's index).
    pub fn with_homing(mut self, cfg: [twoport_control::homing::HomingConfig; N]) -> Self {
        self.board = self.board.with_homing(cfg);
        self
    }
}

impl LocalBoard {
    /// The image the firmware ships ([`excalibur::stiff_wall_board`]).
    pub fn excalibur() -> Result<Self, LinkError> {
        excalibur::stiff_wall_board()
            .map(Self::driven)
            .map_err(|e| LinkError::Image(format!("the Excalibur board image: {e:?}")))
    }
}

impl LocalBoard<Servo<UnilateralWall, f32, 1, SeriesDamper>> {
    /// The passivity image ([`excalibur::stiff_wall_board_with_passivity`]).
    pub fn excalibur_with_passivity() -> Result<Self, LinkError> {
        excalibur::stiff_wall_board_with_passivity()
            .map(Self::driven)
            .map_err(|e| LinkError::Image(format!("the Excalibur passivity image: {e:?}")))
    }
}

/// The 4 kHz image's loop.
pub type LocalFast = LocalBoard<Servo<UnilateralWall>, 1, { fast::REGION_POINTS }>;

impl LocalFast {
    /// The 4 kHz image ([`fast::board`]).
    pub fn excalibur_fast() -> Result<Self, LinkError> {
        fast::board()
            .map(Self::driven)
            .map_err(|e| LinkError::Image(format!("the 4 kHz Excalibur image: {e:?}")))
    }
}

/// The three-axis image's loop.
pub type LocalXyz = LocalBoard<Servo<xyz::XyzWorld, f32, 3>, 3, { xyz::REGION_POINTS }>;

impl LocalXyz {
    /// The three-axis image ([`xyz::board`]).
    pub fn excalibur_xyz() -> Result<Self, LinkError> {
        xyz::board()
            .map(Self::driven)
            .map_err(|e| LinkError::Image(format!("the three-axis Excalibur image: {e:?}")))
    }
}

/// The serial-arm image's loop.
pub type LocalSerialArm =
    LocalBoard<linkage_image::LinkageImageServo<SerialArm>, 3, { linkage_image::REGION_POINTS }>;

/// The delta image's loop.
pub type LocalDelta =
    LocalBoard<linkage_image::LinkageImageServo<Delta>, 3, { linkage_image::REGION_POINTS }>;

impl LocalSerialArm {
    /// The serial-arm image ([`linkage_image::serial_arm_board`]).
    pub fn serial_arm() -> Result<Self, LinkError> {
        linkage_image::serial_arm_board()
            .map(|b: SerialArmBoard| Self::driven(b))
            .map_err(|e| LinkError::Image(format!("the serial-arm image: {e:?}")))
    }
}

impl LocalDelta {
    /// The delta image ([`linkage_image::delta_board`]).
    pub fn delta() -> Result<Self, LinkError> {
        linkage_image::delta_board()
            .map(|b: DeltaBoard| Self::driven(b))
            .map_err(|e| LinkError::Image(format!("the delta image: {e:?}")))
    }
}

impl<D: Drive<N>, const N: usize, const R: usize> BoardPort for LocalBoard<D, N, R> {
    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        // What the images do: the control tick runs each sensor frame as
        // it completes, and the main loop sends what was queued.
        self.link.send(bytes);
        loop {
            let ready = self.board.poll_link(&mut self.link);
            if ready {
                let store = &mut self.store;
                self.board
                    .control_tick_serving(&mut self.link, |b| b.service_config(store));
            }
            self.board.service_config(&mut self.store);
            self.board.flush(&mut self.link);
            if !ready && self.link.drained() {
                return Ok(());
            }
        }
    }
    fn recv(&mut self, buf: &mut [u8], _: Duration) -> Result<usize, LinkError> {
        Ok(self.link.take(buf))
    }
}
