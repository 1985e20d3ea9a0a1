//! The multivariable schemes by name: their design for a matrix plant and
//! their construction ([`crate::mimo`]'s controllers over the registry's
//! single-loop ones), the one place the CLI and Python read.

use std::boxed::Box;
use std::string::String;
use std::vec::Vec;

use super::RunError;
use crate::analysis::mimo::{
    decoupler_design, decoupler_verdict, detune, loops_alone, Decoupling, ElementDesign, LoopRule,
    Realization, SampledLoop,
};
use crate::analysis::Stability;
use crate::delay::Delay;
use crate::error::Error;
use crate::lti::Lti;
use crate::mimo::{Decentralized, Decoupled, Element, InvertedDecoupler, MultiController};
use crate::poly::TransferMatrix;
use crate::registry::{self, Build, DynController, Params};

/// What a multivariable scheme builds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MimoKind {
    /// Decentralized PI loops.
    Pi,
    /// Decentralized Smith predictors.
    Smith,
    /// Smith predictors behind the inverted decoupler.
    Decoupled,
}

/// A multivariable scheme.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MimoScheme {
    /// Its name (`-c` on the command line, `controller=` in Python).
    pub name: &'static str,
    /// What it builds.
    pub kind: MimoKind,
    /// One line for listings and `--help`.
    pub summary: &'static str,
}

/// The multivariable schemes, the default first.
pub static MIMO_SCHEMES: &[MimoScheme] = &[
    MimoScheme {
        name: "pi",
        kind: MimoKind::Pi,
        summary: "decentralized PI loops on the diagonal, each set alone (Ziegler-Nichols, or --rule simc) and detuned together to a biggest log modulus of 2n dB (BLT, Luyben 1986)",
    },
    MimoScheme {
        name: "smith",
        kind: MimoKind::Smith,
        summary: "a Smith predictor on each diagonal channel (decentralized), detuned together to a biggest log modulus of 2n dB",
    },
    MimoScheme {
        name: "decoupled",
        kind: MimoKind::Decoupled,
        summary: "an inverted decoupler (Wade 1997) with a Smith predictor in each decoupled loop (Garrido et al. 2016)",
    },
];

/// The scheme called `name`, or an error that lists them.
pub fn find(name: &str) -> Result<&'static MimoScheme, RunError> {
    MIMO_SCHEMES.iter().find(|s| s.name == name).ok_or_else(|| {
        RunError::Limit(std::format!(
            "no multivariable scheme '{name}': one of {}",
            MIMO_SCHEMES
                .iter()
                .map(|s| s.name)
                .collect::<Vec<_>>()
                .join(", ")
        ))
    })
}

/// A multivariable design: each loop's parameters, the detuning factor
/// and the decoupler (the JSON of `msp tune` and `msp run` for a matrix
/// plant: `scheme`, `f`, `loops`, `decoupler`).
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct MimoDesign {
    /// The scheme's name.
    pub scheme: &'static str,
    /// What it builds.
    #[cfg_attr(feature = "serde", serde(skip))]
    pub kind: MimoKind,
    /// The sample period the design is for (s).
    pub ts: f64,
    /// The `pi` loops' rule alone (`zn`: BLT's; `simc`).
    pub rule: Option<LoopRule>,
    /// The detuning factor (`pi`: BLT's `Kc/F`, `τI·F`; `smith`: each
    /// loop's `λ` times `F`; `decoupled`: 1, the loops being independent).
    pub f: f64,
    /// Each loop's parameters (`kp`, `ti`, …, `lambda`), in diagonal order.
    pub loops: Vec<Params>,
    /// The decoupler's elements (`decoupled`; empty otherwise).
    pub decoupler: Vec<ElementDesign>,
    /// The `pi` loops alone, before the detuning.
    #[cfg_attr(feature = "serde", serde(skip))]
    pub alone: Option<Vec<crate::analysis::mimo::PiLoop>>,
}

fn diagonal(plant: &TransferMatrix) -> Result<Vec<&crate::poly::TransferFunction>, RunError> {
    (0..plant.size())
        .map(|i| {
            plant
                .get(i, i)
                .ok_or(RunError::Invalid(Error::OutOfRange("the matrix's size")))
        })
        .collect()
}

/// Loop `i`'s single-loop scheme and its parameters for `λ` (`None`: the
/// scheme's own choice).
fn smith_loop(g: &crate::poly::TransferFunction, lambda: Option<f64>) -> Result<Params, RunError> {
    registry::find("smith")?
        .tune_with(g, lambda, &[])
        .map_err(|e| {
            RunError::Limit(std::format!(
                "a diagonal channel's Smith predictor ({g}): {e}"
            ))
        })
}

/// Designs `scheme` for `plant` sampled at `ts`; `rule` sets the `pi`
/// loops alone before their detuning (`zn`, BLT's, by default; `simc`).
pub fn design(
    plant: &TransferMatrix,
    scheme: &str,
    rule: Option<&str>,
    ts: f64,
) -> Result<MimoDesign, RunError> {
    let s = find(scheme)?;
    if rule.is_some() && s.kind != MimoKind::Pi {
        return Err(RunError::Limit(std::format!(
            "a rule sets the pi loops of a matrix plant; the {} scheme tunes its loops by λ",
            s.name
        )));
    }
    let n = plant.size();
    let diag = diagonal(plant)?;
    let base = MimoDesign {
        scheme: s.name,
        kind: s.kind,
        ts,
        f: 1.0,
        rule: None,
        loops: Vec::new(),
        decoupler: Vec::new(),
        alone: None,
    };
    match s.kind {
        MimoKind::Pi => {
            let rule = LoopRule::from_name(rule.unwrap_or("zn")).map_err(RunError::Invalid)?;
            let alone = loops_alone(plant, rule).map_err(RunError::Invalid)?;
            let b = detune(plant, alone, None).map_err(RunError::Invalid)?;
            let pi = registry::find("pi")?;
            let loops = b
                .loops
                .iter()
                .zip(&diag)
                .map(|(l, g)| {
                    let set = [
                        (String::from("kp"), l.kp),
                        (String::from("ti"), l.ti),
                        (String::from("td"), 0.0),
                    ];
                    Ok(pi.tune_with(g, None, &set)?)
                })
                .collect::<Result<_, RunError>>()?;
            Ok(MimoDesign {
                f: b.f,
                rule: Some(rule),
                loops,
                alone: Some(b.alone),
                ..base
            })
        }
        MimoKind::Smith => {
            let own: Vec<f64> = diag
                .iter()
                .map(|g| smith_loop(g, None).map(|p| p.lambda().unwrap_or(g.delay.max(ts))))
                .collect::<Result<_, _>>()?;
            let at = |f: f64| -> Result<MimoDesign, RunError> {
                let loops = diag
                    .iter()
                    .zip(&own)
                    .map(|(g, l)| smith_loop(g, Some(l * f)))
                    .collect::<Result<_, _>>()?;
                Ok(MimoDesign {
                    f,
                    loops,
                    ..base.clone()
                })
            };
            // F raised (ln F by bisection) until the sampled loop's biggest
            // log modulus is 2n dB, as BLT does for PI loops
            #[allow(clippy::cast_precision_loss)]
            let target = 2.0 * n as f64;
            let lcm = |d: &MimoDesign| -> Result<f64, RunError> {
                let loops = loops_of(plant, d)?;
                let refs: Vec<&dyn crate::loop_controller::LoopController<f64>> =
                    loops.iter().map(|c| &**c as _).collect();
                let l = SampledLoop::new(plant, ts, &refs, None).map_err(RunError::Invalid)?;
                Ok(if l.verdict().stable == Some(true) {
                    l.lcm()
                } else {
                    f64::INFINITY
                })
            };
            let first = at(1.0)?;
            if lcm(&first)? <= target {
                return Ok(first);
            }
            let (mut lo, mut hi) = (0.0f64, 1.0f64);
            while lcm(&at(hi.exp())?)? > target {
                lo = hi;
                hi += 1.0;
                if hi > 6.0 {
                    return Err(RunError::Invalid(Error::Numerical(
                        "no detuning of the Smith predictors' λ up to e^6 brings the biggest log modulus down to 2n dB",
                    )));
                }
            }
            for _ in 0..30 {
                let mid = 0.5 * (lo + hi);
                if lcm(&at(mid.exp())?)? > target {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            at(hi.exp())
        }
        MimoKind::Decoupled => {
            let loops = diag
                .iter()
                .map(|g| smith_loop(g, None))
                .collect::<Result<_, _>>()?;
            let decoupler = decoupler_design(plant, ts).map_err(RunError::Invalid)?;
            let d = MimoDesign {
                loops,
                decoupler,
                ..base
            };
            if let Some(dec) = decoupling_of(n, &d)? {
                let v = decoupler_verdict(&*dec, n);
                if v.stable != Some(true) {
                    return Err(RunError::Limit(std::format!(
                        "the inverted decoupler's own loop is unstable ({}): det G(z) has a zero outside the unit circle (a transmission zero in the right half-plane), which inverted decoupling cannot cancel; -c smith or -c pi control this plant without a decoupler",
                        v.reason
                    )));
                }
            }
            Ok(d)
        }
    }
}

/// Each loop's controller of design `d` (the registry's `pi` or `smith`).
pub fn loops_of(plant: &TransferMatrix, d: &MimoDesign) -> Result<Vec<DynController>, RunError> {
    let name = if d.kind == MimoKind::Pi {
        "pi"
    } else {
        "smith"
    };
    let scheme = registry::find(name)?;
    diagonal(plant)?
        .iter()
        .zip(&d.loops)
        .map(|(g, p)| Ok(scheme.build_with(p, g, &Build::unlimited(d.ts))?))
        .collect()
}

/// A decoupling element as the host builds it.
type HostElement = Element<f64, 8, Vec<f64>>;

/// One element's block and line.
fn element(e: &ElementDesign) -> Result<HostElement, Error> {
    // ascending powers of z⁻¹ padded to one length: descending powers of z
    let len = e.num.len().max(e.den.len());
    let pad = |p: &[f64]| {
        let mut v = p.to_vec();
        v.resize(len, 0.0);
        v
    };
    let block = Lti::from_discrete_tf(&pad(&e.num), &pad(&e.den))?;
    #[allow(clippy::cast_precision_loss)]
    let line = Delay::new_in(e.delay as f64)?;
    Ok(Element::new(block, line))
}

/// The decoupler of `elements` for an `N×N` plant.
fn decoupler<const N: usize>(
    elements: &[ElementDesign],
) -> Result<InvertedDecoupler<f64, N, 8, Vec<f64>>, Error> {
    let mut out: [[Option<HostElement>; N]; N] =
        core::array::from_fn(|_| core::array::from_fn(|_| None));
    for e in elements {
        if matches!(e.realization, Realization::Absent { .. }) {
            continue;
        }
        if let Some(slot) = out.get_mut(e.row).and_then(|r| r.get_mut(e.col)) {
            *slot = Some(element(e)?);
        }
    }
    InvertedDecoupler::new(out)
}

/// Runs `$body` with `N` the plant's size as a constant (2 to 8).
macro_rules! with_size {
    ($n:expr, $N:ident => $body:expr) => {
        match $n {
            2 => {
                const $N: usize = 2;
                $body
            }
            3 => {
                const $N: usize = 3;
                $body
            }
            4 => {
                const $N: usize = 4;
                $body
            }
            5 => {
                const $N: usize = 5;
                $body
            }
            6 => {
                const $N: usize = 6;
                $body
            }
            7 => {
                const $N: usize = 7;
                $body
            }
            8 => {
                const $N: usize = 8;
                $body
            }
            _ => Err(Error::OutOfRange("a decoupler for 2 to 8 loops")),
        }
    };
}

/// The decoupler of design `d` as the analysis reads it (`None` without one).
pub fn decoupling_of(n: usize, d: &MimoDesign) -> Result<Option<Box<dyn Decoupling>>, RunError> {
    if d.kind != MimoKind::Decoupled {
        return Ok(None);
    }
    with_size!(n, N => decoupler::<N>(&d.decoupler).map(|x| Some(Box::new(x) as Box<dyn Decoupling>)))
        .map_err(RunError::Invalid)
}

/// The controller of design `d` for `plant`, ready to run.
pub fn controller(
    plant: &TransferMatrix,
    d: &MimoDesign,
) -> Result<Box<dyn MultiController<f64> + Send>, RunError> {
    let loops = loops_of(plant, d)?;
    if d.kind != MimoKind::Decoupled {
        return Ok(Box::new(Decentralized::new(loops)));
    }
    let n = plant.size();
    with_size!(n, N => {
        let dec = decoupler::<N>(&d.decoupler)?;
        let arr: [DynController; N] = loops
            .try_into()
            .map_err(|_| Error::OutOfRange("one controller per loop"))?;
        Ok(Box::new(Decoupled::new(arr, dec)) as Box<dyn MultiController<f64> + Send>)
    })
    .map_err(RunError::Invalid)
}

/// The closed loop of design `d` on `plant`: its stability verdict, its
/// decoupler's own (with a decoupler) and its biggest log modulus (dB).
pub fn analyse(
    plant: &TransferMatrix,
    d: &MimoDesign,
) -> Result<(Stability, Option<Stability>, f64), RunError> {
    let loops = loops_of(plant, d)?;
    let refs: Vec<&dyn crate::loop_controller::LoopController<f64>> =
        loops.iter().map(|c| &**c as _).collect();
    let dec = decoupling_of(plant.size(), d)?;
    let l = SampledLoop::new(plant, d.ts, &refs, dec.as_deref()).map_err(RunError::Invalid)?;
    Ok((l.verdict(), l.decoupler_verdict(), l.lcm()))
}
