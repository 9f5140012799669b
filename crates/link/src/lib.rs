//! # twoport-link
//!
//! The board-host protocol (framing, CRC, sequence numbers, messages) will
//! live here. It is not implemented yet: this crate deliberately exports
//! nothing, so nothing can depend on a protocol that does not exist.
#![no_std]
#![forbid(unsafe_code)]
