//! The library `msp` (package `msp-deadtime`) under the workspace's old
//! package name `msp`: everything it has, re-exported.
#![no_std]

pub use msp::*;
