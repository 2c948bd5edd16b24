//! What a run writes: [`output`] (the .vtu fields, summary.json entries and contact CSV of a
//! step), [`history`] (history.csv and the force-travel plot), [`table`] (the table on stdout),
//! [`supports`] (the reaction of each `[[boundary]]` group), [`probe`] and [`thickness_probe`]
//! (fields along a line and through the thickness, with the shears of [`equilibrium_shear`] and
//! the [`recovered_stresses`] fitted on a [`patch`] with the [`face_tractions`]) and
//! [`plot`] (PNG/SVG line plots).

pub mod equilibrium_shear;
pub mod face_tractions;
pub mod history;
pub mod output;
pub mod plastic;
pub mod patch;
pub mod plot;
pub mod probe;
pub mod recovered_stresses;
pub mod supports;
pub mod table;
pub mod thickness_probe;
