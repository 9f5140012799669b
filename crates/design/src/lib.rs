//! # twoport-design (in progress)
#![forbid(unsafe_code)]
