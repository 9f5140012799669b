//! The board from Python: its servo loop on the board (or in Rust), its
//! stream as numpy arrays, its VE's surfaces sent from Python.

use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::time::Duration;
use twoport_host::{
    BoardPort, Contact, HostBoard, LinkError, Pace, PcBoard, SerialBoard, SimulatedBoard, State,
};

/// A board: a real one over a serial port, the firmware in QEMU through
/// its pty, or the shipped Excalibur image on a simulated device in this
/// process. Its servo loop runs on the board (or in Rust), never in
/// Python; Python reads its streamed states as numpy arrays and sends its
/// VE's surfaces. Closing it (or letting it go) disarms it.
#[pyclass(unsendable, module = "twoport")]
pub(crate) struct Board {
    inner: Option<HostBoard<Box<dyn BoardPort + Send>>>,
}

fn link(e: LinkError) -> PyErr {
    PyRuntimeError::new_err(e.to_string())
}

impl Board {
    fn open(&mut self) -> PyResult<&mut HostBoard<Box<dyn BoardPort + Send>>> {
        self.inner
            .as_mut()
            .ok_or_else(|| PyRuntimeError::new_err("the board is closed"))
    }
}

/// The states as numpy arrays: one entry per field, axis-indexed fields
/// as (states, axes).
fn arrays<'py>(py: Python<'py>, states: &[State], axes: usize) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let col = |f: fn(&State) -> f64| PyArray1::from_iter(py, states.iter().map(f));
    d.set_item("tick", col(|s| f64::from(s.tick)))?;
    d.set_item("faults", col(|s| f64::from(s.faults)))?;
    d.set_item("ve_seq", col(|s| f64::from(s.ve_seq)))?;
    let per_axis = |f: fn(&twoport_host::AxisState) -> f64| -> PyResult<Bound<'py, PyArray2<f64>>> {
        let v: Vec<f64> = states
            .iter()
            .flat_map(|s| (0..axes).map(move |i| f(&s.axes[i])))
            .collect();
        PyArray1::from_vec(py, v).reshape([states.len(), axes])
    };
    d.set_item("position_m", per_axis(|a| a.position_m)?)?;
    d.set_item("velocity_mps", per_axis(|a| a.velocity_mps)?)?;
    d.set_item("load_cell_n", per_axis(|a| a.load_cell_n)?)?;
    d.set_item("commanded_n", per_axis(|a| a.commanded_n)?)?;
    d.set_item("actuator_n", per_axis(|a| a.actuator_n)?)?;
    d.set_item("ve_position_m", per_axis(|a| a.ve_position_m)?)?;
    Ok(d)
}

fn contact(name: &str) -> PyResult<Contact> {
    match name {
        "held" => Ok(Contact::Held),
        "above" => Ok(Contact::Above),
        "below" => Ok(Contact::Below),
        "free" => Ok(Contact::Free),
        other => Err(PyValueError::new_err(format!(
            "contact {other:?}: one of \"held\", \"above\", \"below\", \"free\""
        ))),
    }
}

#[pymethods]
impl Board {
    /// Open the board of `axes` axes at the serial port `path`.
    #[staticmethod]
    #[pyo3(signature = (path, axes=1))]
    fn serial(py: Python<'_>, path: String, axes: u8) -> PyResult<Board> {
        let b = py.detach(move || {
            let port: Box<dyn BoardPort + Send> = Box::new(SerialBoard::open(&path)?);
            HostBoard::open(port, axes)
        });
        Ok(Board {
            inner: Some(b.map_err(link)?),
        })
    }

    /// The shipped Excalibur image on a simulated device in this process,
    /// ticking with the wall clock, a hand pushing `hand_n` (N) along +x
    /// while the board's outputs are on.
    #[staticmethod]
    #[pyo3(signature = (hand_n=2.0))]
    fn simulated(hand_n: f32) -> PyResult<Board> {
        let port: Box<dyn BoardPort + Send> =
            Box::new(SimulatedBoard::excalibur(hand_n, Pace::RealTime).map_err(link)?);
        Ok(Board {
            inner: Some(HostBoard::open(port, 1).map_err(link)?),
        })
    }

    /// The Excalibur's PC image (its region proven for up to 5 ms from
    /// sample to force) on the PC's loop, in a thread of its own, against a simulated device exchanged with as a USB device is
    /// (the path a Falcon or a Haply board takes), the hand pushing
    /// `hand_n` (N) along +x while the outputs are on.
    #[staticmethod]
    #[pyo3(signature = (hand_n=2.0))]
    fn pc_simulated(hand_n: f32) -> PyResult<Board> {
        let port: Box<dyn BoardPort + Send> =
            Box::new(PcBoard::excalibur_simulated(hand_n).map_err(link)?);
        Ok(Board {
            inner: Some(HostBoard::open(port, 1).map_err(link)?),
        })
    }

    /// The device `name` (`"haply-2diy"`, `"falcon"` or `"touch"`, as
    /// `twoport devices` lists them) at `path` (a serial port; a Touch's
    /// name in Touch Setup, "" for the default one), its image running in
    /// this computer's servo loop; `firmware` is the Falcon's firmware file
    /// (Novint's, not shipped), or a Touch's HD library where it is not the
    /// system's. Each failure says what to do.
    /// `unproven_gains`, where given, says why its image should accept
    /// gains outside its proven region: the user's explicit choice, which
    /// the loop logs.
    #[staticmethod]
    #[pyo3(signature = (name, path, firmware=None, unproven_gains=None))]
    fn device(
        name: &str,
        path: &str,
        firmware: Option<std::path::PathBuf>,
        unproven_gains: Option<&str>,
    ) -> PyResult<Board> {
        let (pc, axes) =
            twoport_host::attached::open_with(name, path, firmware.as_deref(), unproven_gains)
                .map_err(link)?;
        let port: Box<dyn BoardPort + Send> = Box::new(pc);
        Ok(Board {
            inner: Some(HostBoard::open(port, axes).map_err(link)?),
        })
    }

    /// Where the device `name`'s image calibrates (rad, a joint each):
    /// hold the handle there and `calibrate` there after `device`.
    #[staticmethod]
    fn rest_pose(name: &str) -> PyResult<Vec<f64>> {
        twoport_host::attached::rest_pose(name).map_err(link)
    }

    /// The servo loop's timing where it runs on this computer
    /// (`pc_simulated`, a device's driver): ticks, late ticks, and the
    /// period's, the device exchange's and the latency's p50/p99/max (s);
    /// `None` where the board runs its own loop.
    fn loop_timing<'py>(&mut self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(t) = self.open()?.port().loop_timing() else {
            return Ok(None);
        };
        let d = PyDict::new(py);
        d.set_item("ticks", t.ticks)?;
        d.set_item("late", t.late)?;
        for (name, p) in [
            ("period_s", t.period_s),
            ("io_s", t.io_s),
            ("latency_s", t.latency_s),
        ] {
            let q = PyDict::new(py);
            q.set_item("p50", p.p50)?;
            q.set_item("p99", p.p99)?;
            q.set_item("max", p.max)?;
            d.set_item(name, q)?;
        }
        Ok(Some(d))
    }

    /// What the board can do: its period (s), and per axis its force
    /// limits and its proven region's envelope.
    fn spec<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = *self.open()?.spec();
        let d = PyDict::new(py);
        d.set_item("period_s", s.period_s())?;
        d.set_item("linkage", s.linkage)?;
        d.set_item("link_bytes_per_s", s.link_bytes_per_s)?;
        d.set_item("count_hz", s.count_hz)?;
        d.set_item("worst_latency_s", s.worst_latency_s())?;
        d.set_item("latency_budget_s", s.latency_budget_s)?;
        let axes = pyo3::types::PyList::empty(py);
        for a in s.axes.iter() {
            let x = PyDict::new(py);
            x.set_item("peak_force_n", a.peak_force_n)?;
            x.set_item("continuous_force_n", a.continuous_force_n)?;
            x.set_item("max_velocity_mps", a.max_velocity_mps)?;
            x.set_item(
                "workspace_m",
                a.workspace_nm
                    .map(|(lo, hi)| (f64::from(lo) * 1e-9, f64::from(hi) * 1e-9)),
            )?;
            let r = &a.region;
            let (limit, b_at) = r.limit();
            x.set_item(
                "display",
                if r.is_impedance() {
                    "impedance"
                } else {
                    "admittance"
                },
            )?;
            x.set_item("b_range_nspm", r.b_range_nspm())?;
            x.set_item(
                if r.is_impedance() {
                    "k_max_npm"
                } else {
                    "m_min_kg"
                },
                limit,
            )?;
            x.set_item("b_at_limit_nspm", b_at)?;
            if let Some(reg) = r.regulator() {
                x.set_item("regulator", reg)?;
            }
            axes.append(x)?;
        }
        d.set_item("axes", axes)?;
        Ok(d)
    }

    /// Home every axis into its stop and wait until the board is
    /// calibrated (at most `timeout_s` s), the link served with the GIL
    /// released; a fault on the way raises naming it.
    #[pyo3(signature = (timeout_s=30.0))]
    fn home(&mut self, py: Python<'_>, timeout_s: f64) -> PyResult<()> {
        if !(timeout_s.is_finite() && timeout_s >= 0.0) {
            return Err(PyValueError::new_err(format!(
                "timeout_s {timeout_s}: not a time"
            )));
        }
        let b = self.open()?;
        py.detach(|| b.home(Duration::from_secs_f64(timeout_s.min(3600.0))))
            .map(|_| ())
            .map_err(link)
    }

    /// The newest state read, as a dict (`mode` by name, per-axis fields
    /// as lists), or None before any.
    fn latest<'py>(&mut self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(s) = self.open()?.latest().copied() else {
            return Ok(None);
        };
        let d = PyDict::new(py);
        d.set_item("tick", s.tick)?;
        d.set_item("mode", format!("{:?}", s.mode).to_lowercase())?;
        d.set_item("faults", s.faults)?;
        d.set_item("ve_seq", s.ve_seq)?;
        let n = self.open()?.axes();
        let axis = |f: fn(&twoport_host::AxisState) -> f64| -> Vec<f64> {
            s.axes.iter().take(n).map(f).collect()
        };
        d.set_item("position_m", axis(|a| a.position_m))?;
        d.set_item("velocity_mps", axis(|a| a.velocity_mps))?;
        d.set_item("actuator_n", axis(|a| a.actuator_n))?;
        d.set_item("ve_position_m", axis(|a| a.ve_position_m))?;
        Ok(Some(d))
    }

    /// Set one parameter of the board's own VE on `axis` (disarmed only):
    /// "surface" (m), "stiffness" (N/m) or "damping" (N s/m).
    fn set_ve_param(&mut self, axis: usize, name: &str, value: f64) -> PyResult<()> {
        use twoport_host::VeParam;
        let setting = match name {
            "surface" => VeParam::surface_m(value),
            "stiffness" => VeParam::stiffness_npm(value),
            "damping" => VeParam::damping_nspm(value),
            other => {
                return Err(PyValueError::new_err(format!(
                    "{other:?}: one of \"surface\", \"stiffness\", \"damping\""
                )))
            }
        }
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
        match self.open()?.set_ve_param(axis, setting) {
            Ok(_) => Ok(()),
            Err(
                e @ (LinkError::BadValue { .. }
                | LinkError::Axes { .. }
                | LinkError::OutOfRange { .. }),
            ) => Err(PyValueError::new_err(e.to_string())),
            Err(e) => Err(link(e)),
        }
    }

    /// Tell a disarmed board where each axis stands (m).
    fn calibrate(&mut self, position_m: Vec<f64>) -> PyResult<()> {
        self.open()?
            .calibrate(&position_m)
            .map(|_| ())
            .map_err(link)
    }

    /// Arm: the coupling runs and the force comes on.
    fn arm(&mut self) -> PyResult<()> {
        self.open()?.arm().map(|_| ()).map_err(link)
    }

    /// Disarm: zero force at once.
    fn disarm(&mut self) -> PyResult<()> {
        self.open()?.disarm().map(|_| ()).map_err(link)
    }

    /// Stream the state every `every_ticks` ticks (0: none).
    fn stream(&mut self, every_ticks: u32) -> PyResult<()> {
        self.open()?.stream(every_ticks).map_err(link)
    }

    /// Run the VE on the host (disarmed only).
    #[pyo3(signature = (ramp_ticks=1, deadline_ticks=50))]
    fn host_ve(&mut self, ramp_ticks: u32, deadline_ticks: u32) -> PyResult<()> {
        self.open()?
            .host_ve(ramp_ticks, deadline_ticks)
            .map(|_| ())
            .map_err(link)
    }

    /// Send each axis's VE surface (m) and what it is ("held", "above",
    /// "below", "free"); returns the update's number.
    fn send_ve(&mut self, position_m: Vec<f64>, contact: Vec<String>) -> PyResult<u32> {
        let c = contact
            .iter()
            .map(|c| self::contact(c))
            .collect::<PyResult<Vec<_>>>()?;
        self.open()?.send_ve(&position_m, &c).map_err(link)
    }

    /// Read what the board sent and feed its watchdog (call at least
    /// every 20 ms while armed); returns the states read.
    fn poll(&mut self) -> PyResult<usize> {
        self.open()?.poll().map_err(link)
    }

    /// Run the link for `seconds` (s), reading the stream and feeding the
    /// watchdog, with the GIL released: the loop a script waits in.
    fn run_for(&mut self, py: Python<'_>, seconds: f64) -> PyResult<()> {
        if !(seconds.is_finite() && seconds >= 0.0) {
            return Err(PyValueError::new_err(format!(
                "seconds {seconds}: not a time"
            )));
        }
        let b = self.open()?;
        py.detach(|| {
            let end = std::time::Instant::now() + Duration::from_secs_f64(seconds);
            while std::time::Instant::now() < end {
                b.poll()?;
            }
            Ok(())
        })
        .map_err(link)
    }

    /// The states streamed since the last call, as numpy arrays.
    fn take_states<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let b = self.open()?;
        let axes = b.axes();
        let states = b.take_states();
        arrays(py, &states, axes)
    }

    /// Disarm and let the board go.
    fn close(&mut self) -> PyResult<()> {
        match self.inner.take() {
            Some(b) => b.close().map_err(link),
            None => Ok(()),
        }
    }
}
