//! `[output]`: which files a run writes, the plot's axis and group, the loaded-zone threshold,
//! and the probes (`[[output.probe]]`, `[[output.thickness_probe]]`).

use super::Problem;
use super::values::Fraction;
use serde::Deserialize;
use stamp::{Result, StampError};
use toml::Spanned;

/// One `[[output.probe]]` table (the probe itself: outputs/probe.rs).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeSpec {
    pub name: String,
    pub from: [f64; 2],
    pub to: [f64; 2],
    #[serde(default)]
    pub points: Option<usize>,
}

/// A probe's `name` (it names files): 1 to 64 letters, digits, '_' or '-', and no other probe of
/// its kind (`what`: "probes", "thickness probes") named alike.
fn check_probe_name(p: &Problem, span: std::ops::Range<usize>, key: &str, name: &str, names: &mut std::collections::BTreeSet<String>, what: &str) -> Result<()> {
    if name.is_empty() || name.len() > 64 || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') {
        return Err(p.error_at(span, &format!("{key}.name"), format!("{} must be 1 to 64 letters, digits, '_' or '-' (it names files)", stamp::quote(name))));
    }
    if !names.insert(name.to_string()) {
        return Err(p.error_at(span, &format!("{key}.name"), format!("two {what} are named {}", stamp::quote(name))));
    }
    Ok(())
}

/// Check the probes of a problem file (called by [`Problem::parse`]; see outputs/probe.rs) (names, ends, number of points), with file, line and key.
pub fn check_probes(p: &Problem, probes: &[Spanned<ProbeSpec>]) -> Result<()> {
    let mut names = std::collections::BTreeSet::new();
    for (i, s) in probes.iter().enumerate() {
        let spec = s.get_ref();
        let key = format!("output.probe[{i}]");
        check_probe_name(p, s.span(), &key, &spec.name, &mut names, "probes")?;
        if spec.from.iter().chain(&spec.to).any(|v| !v.is_finite()) {
            return Err(p.error_at(s.span(), &key, format!("from = {:?} and to = {:?} must be finite", spec.from, spec.to)));
        }
        if spec.from == spec.to {
            return Err(p.error_at(s.span(), &format!("{key}.to"), format!("the line has no length: from = to = {:?}", spec.from)));
        }
        if let Some(n) = spec.points {
            if !(2..=100_000).contains(&n) {
                return Err(p.error_at(s.span(), &format!("{key}.points"), format!("expected 2 to 100000 points, got {n}")));
            }
        }
    }
    Ok(())
}

/// The default rows per layer.
pub const DEFAULT_POINTS_PER_LAYER: usize = 9;

/// One `[[output.thickness_probe]]` table (the probe itself: outputs/thickness_probe.rs).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ThicknessProbeSpec {
    pub name: String,
    pub at: [f64; 2],
    #[serde(default)]
    pub points_per_layer: Option<usize>,
    /// `"law"` (default): s13, s23 by each layer's 3D law; `"equilibrium"`: integrated from the
    /// bottom face (outputs/equilibrium_shear.rs).
    #[serde(default)]
    pub transverse_shear: Option<String>,
    /// `"recovered"`: all six stresses recovered (in-plane by patch fits, s13, s23, s33 integrated
    /// from 3D equilibrium, outputs/recovered_stresses.rs); `"law"`: each layer's 3D law at the
    /// Gauss points, extrapolated (with `transverse_shear`). The default: see
    /// [`ThicknessProbeSpec::recovered`].
    #[serde(default)]
    pub stresses: Option<String>,
}

impl ThicknessProbeSpec {
    /// Whether the probe recovers its stresses: `stresses = "recovered"`, or neither `stresses`
    /// nor `transverse_shear` given (a probe with `transverse_shear` reads the law's stresses, as
    /// it always did).
    pub fn recovered(&self) -> bool {
        match &self.stresses {
            Some(s) => s == "recovered",
            None => self.transverse_shear.is_none() && DEFAULT_RECOVERED,
        }
    }
}

/// Whether a thickness probe recovers its stresses when the file says nothing.
pub const DEFAULT_RECOVERED: bool = true;

/// Names, points and counts, with file, line and key; a laminate is needed.
pub fn check_thickness_probes(p: &Problem, probes: &[Spanned<ThicknessProbeSpec>]) -> Result<()> {
    let mut names = std::collections::BTreeSet::new();
    for (i, s) in probes.iter().enumerate() {
        let spec = s.get_ref();
        let key = format!("output.thickness_probe[{i}]");
        let plate = p.spec.plate.get_ref();
        if plate.layers.is_none() && plate.surfaces() < 3 {
            return Err(p.error_at(
                s.span(),
                &key,
                "the stresses through the thickness are those of the 3D law: the plate needs `layers` or `surfaces` = 3 to 5 (the two-surface plate has the paper's plane-stress law)",
            ));
        }
        check_probe_name(p, s.span(), &key, &spec.name, &mut names, "thickness probes")?;
        if spec.at.iter().any(|v| !v.is_finite()) {
            return Err(p.error_at(s.span(), &format!("{key}.at"), format!("must be two finite numbers, got {:?}", spec.at)));
        }
        if let Some(t) = &spec.transverse_shear {
            if t != "law" && t != "equilibrium" {
                return Err(p.error_at(s.span(), &format!("{key}.transverse_shear"), format!("expected \"law\" or \"equilibrium\", got {}", stamp::quote(t))));
            }
        }
        if let Some(t) = &spec.stresses {
            if t != "law" && t != "recovered" {
                return Err(p.error_at(s.span(), &format!("{key}.stresses"), format!("expected \"recovered\" or \"law\", got {}", stamp::quote(t))));
            }
            if t == "recovered" && spec.transverse_shear.is_some() {
                return Err(p.error_at(
                    s.span(),
                    &format!("{key}.transverse_shear"),
                    "applies to stresses = \"law\": the recovered stresses integrate s13 and s23 from equilibrium themselves (remove `transverse_shear`, or write stresses = \"law\")",
                ));
            }
        }
        if let Some(n) = spec.points_per_layer {
            if !(2..=1000).contains(&n) {
                return Err(p.error_at(s.span(), &format!("{key}.points_per_layer"), format!("expected 2 to 1000 points (the layer's faces among them), got {n}")));
            }
        }
    }
    Ok(())
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum PlotAxis {
    X1,
    #[default]
    X2,
    /// Arc length along `plot_group` (a curve group), in reference coordinates.
    Arc,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Write one .vtu per converged step (and the .pvd).
    #[serde(default = "yes")]
    pub vtu: bool,
    /// Write the contact-pressure CSV per step and punch.
    #[serde(default = "yes")]
    pub csv: bool,
    /// Draw the probe plots (PNG and SVG); with no `[[output.probe]]`, a default probe through the
    /// first contact point along x1. On by default.
    #[serde(default = "yes")]
    pub plot: bool,
    #[serde(default)]
    pub plot_axis: PlotAxis,
    /// Only these nodes in the plot (required for plot_axis = "arc": a curve group).
    #[serde(default)]
    pub plot_group: Option<Spanned<String>>,
    /// Every converged step (true) or the targets only (false).
    #[serde(default = "yes")]
    pub every_step: bool,
    /// A node is in the loaded zone when |lambda| > loaded_threshold * max |lambda| (0.5 %: docs/verification/paper.md,
    /// "The paper's benchmark").
    #[serde(default = "default_threshold")]
    pub loaded_threshold: Fraction,
    /// Lines along which the fields are sampled (see outputs/probe.rs).
    #[serde(default)]
    pub probe: Vec<Spanned<ProbeSpec>>,
    /// Points whose fields through the thickness are written (see outputs/thickness_probe.rs).
    #[serde(default)]
    pub thickness_probe: Vec<Spanned<ThicknessProbeSpec>>,
}

fn yes() -> bool {
    true
}
fn default_threshold() -> Fraction {
    Fraction(0.005)
}

impl Default for OutputSpec {
    fn default() -> Self {
        OutputSpec {
            vtu: true,
            csv: true,
            plot: true,
            plot_axis: PlotAxis::X2,
            plot_group: None,
            every_step: true,
            loaded_threshold: default_threshold(),
            probe: Vec::new(),
            thickness_probe: Vec::new(),
        }
    }
}

impl Problem {
    /// The checks of `[output]`: the probes, and a group for the arc-length axis.
    pub(super) fn check_output(&self) -> Result<()> {
        let s = &self.spec;
        check_probes(self, &s.output.probe)?;
        check_thickness_probes(self, &s.output.thickness_probe)?;
        if s.output.plot_axis == PlotAxis::Arc && s.output.plot_group.is_none() {
            return Err(StampError::Input {
                file: self.path.display().to_string(),
                message: "output.plot_axis = \"arc\" needs output.plot_group (a curve group)".into(),
            });
        }
        Ok(())
    }
}
