//! What a board image provides to the portable loop: its peripherals,
//! behind one trait, so that the control interrupt's body
//! ([`Board::control_tick`](crate::Board::control_tick)) is written once
//! for every image, and a host test can stand in for the hardware.

/// One tick's sensors of a device of `N` axes (one by default) as the
/// peripherals give them, before any scaling, all latched at one instant.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RawSensors<const N: usize = 1> {
    /// Each axis's encoder timer count (its low `bits` are meaningful).
    pub encoder_raw: [u32; N],
    /// Each axis's load-cell ADC reading, offset removed (counts; signed).
    pub load_cell_counts: [i32; N],
    /// Whether the dead-man switch is closed (the hand is on the handle).
    pub dead_man_closed: bool,
    /// The encoder count each axis's index pulse latched since the last
    /// sample, where its encoder has an index and it passed.
    pub index_raw: [Option<u32>; N],
}

impl<const N: usize> Default for RawSensors<N> {
    fn default() -> Self {
        RawSensors {
            encoder_raw: [0; N],
            load_cell_counts: [0; N],
            dead_man_closed: false,
            index_raw: [None; N],
        }
    }
}

/// The peripherals of a board of `N` axes (one by default), as the loop
/// uses them.
///
/// The image owns the timer that calls the control interrupt; the loop
/// needs only what is below. Every method is called with the board's lock
/// held, so none of them may wait long: `write` only ever sends a queued
/// frame, and `sample` waits only for the conversion it started.
pub trait BoardSupport<const N: usize = 1> {
    /// Latch every sensor of every axis at one instant and return the
    /// readings: the encoder counts, the load cells (starting their
    /// conversions and waiting for them) and the dead-man input.
    fn sample(&mut self) -> RawSensors<N>;
    /// Command the amplifiers, every axis in the same update: a signed
    /// duty each, ±[`DUTY_FULL_SCALE`] at full-scale force, 0 for none.
    ///
    /// [`DUTY_FULL_SCALE`]: crate::DUTY_FULL_SCALE
    fn set_duty(&mut self, duty: [i16; N]);
    /// Switch the amplifier's outputs on or off (a gate-driver enable, a
    /// timer's main output enable). Off at boot, before the first call;
    /// the loop turns them on only while homing or armed.
    fn set_outputs(&mut self, on: bool);
    /// Feed the watchdog: the loop does once a tick, and a processor-in-the-
    /// loop board as it waits for its host, so that only a loop that has
    /// stopped lets it bite. Boards without one do nothing.
    fn feed_watchdog(&mut self);
    /// A byte the link received, if one is waiting.
    fn read_byte(&mut self) -> Option<u8>;
    /// Send bytes on the link.
    fn write(&mut self, bytes: &[u8]);
    /// A free-running count for timing the loop: core cycles on hardware,
    /// instructions in an emulator with `-icount`, 0 where there is none.
    fn cycles(&mut self) -> u32;
    /// The control period in [`cycles`](Self::cycles)' count, for the
    /// deadline and jitter checks; 0 where the host paces the ticks
    /// (processor in the loop) or there is no count.
    fn cycles_per_tick(&self) -> u32;
    /// The latency, in [`cycles`](Self::cycles)' count, of the force the
    /// device applied at this tick's [`sample`](Self::sample), where the
    /// device applies a command later than [`set_duty`](Self::set_duty)
    /// (a device on a bus takes the command with its next exchange). `None`
    /// (the default): the amplifiers take it at `set_duty`, and the loop
    /// times the latency itself.
    fn force_latency(&self) -> Option<u32> {
        None
    }
}
