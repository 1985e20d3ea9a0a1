//! `msp list`.

use crate::error::CliError;
use crate::export;
use msp::registry;

pub(crate) fn list() -> Result<(), CliError> {
    export::outln!("controllers:")?;
    for s in registry::SCHEMES {
        let aliases = if s.aliases.is_empty() {
            String::new()
        } else {
            format!(" (alias {})", s.aliases.join(", "))
        };
        export::outln!("  {:<22}{aliases}  {}", s.name, s.summary)?;
        export::outln!(
            "  {:<22}  params: {}; design (--set before tuning): {}; source: {}",
            "",
            s.params.join(", "),
            s.design.join(", "),
            s.source
        )?;
    }
    export::outln!("controllers of a matrix plant (--plant \"[g11, g12; g21, g22]\"; --rule zn or simc for pi):")?;
    for s in msp::study::MIMO_SCHEMES {
        export::outln!("  {:<22}  {}", s.name, s.summary)?;
    }
    export::outln!("tuning rules for `pid`/`pi` (--rule): imc (IMC-PID, Bag (2022) Eqs. 3.25-3.27), simc (Skogestad (2003)), amigo (Astrom & Hagglund (2004), with set-point weight b), and from Ku, Tu:")?;
    for r in msp::tuning::PI_RULES.iter().chain(msp::tuning::PID_RULES) {
        export::outln!(
            "  {:<20} Kc = {} Ku, Ti = {} Tu, Td = {} Tu  ({})",
            r.name,
            r.a,
            r.b,
            r.c,
            r.note
        )?;
    }
    Ok(())
}
