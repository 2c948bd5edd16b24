//! The raw binding: bindgen's output over the allowlist of build.rs, and the MPI calls of
//! `shim.c`.
#![allow(non_upper_case_globals, non_camel_case_types, non_snake_case, dead_code, clippy::all)]

include!(concat!(env!("OUT_DIR"), "/bindings.rs"));

extern "C" {
    pub fn stamp_petsc_world_rank(rank: *mut i32) -> i32;
    pub fn stamp_petsc_world_size(size: *mut i32) -> i32;
    /// op: 0 max, 1 min, 2 sum.
    pub fn stamp_petsc_allreduce_u64(buf: *mut u64, n: i32, op: i32) -> i32;
    /// op: 0 max, 1 min, 2 sum.
    pub fn stamp_petsc_allreduce_f64(buf: *mut f64, n: i32, op: i32) -> i32;
    pub fn stamp_petsc_bcast_bytes(buf: *mut std::ffi::c_void, n: i32, root: i32) -> i32;
    pub fn stamp_petsc_barrier() -> i32;
    pub fn stamp_petsc_abort(code: i32) -> i32;
    pub fn stamp_petsc_barrier_within(seconds: f64, done: *mut i32) -> i32;
}
