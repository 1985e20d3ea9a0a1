//! What a registry scheme does with a plant: tune it, build it (in f64 or
//! f32, for a process or a cascade), describe its design.

use super::*;

impl Scheme {
    /// Tunes on `model`, applying `overrides` (design keys before tuning,
    /// parameter names after). Unknown names are an error naming the valid ones.
    pub fn tune_with(
        &'static self,
        model: &TransferFunction,
        lambda: Option<f64>,
        overrides: &[(String, f64)],
    ) -> Result<Params, RegistryError> {
        self.tune_rule(model, lambda, None, overrides)
    }

    /// [`Scheme::tune_with`] with a named rule (`--rule`).
    pub fn tune_rule(
        &'static self,
        model: &TransferFunction,
        lambda: Option<f64>,
        rule: Option<&str>,
        overrides: &[(String, f64)],
    ) -> Result<Params, RegistryError> {
        self.tune_process(model, None, lambda, rule, overrides)
    }

    /// The designed quantities of this scheme with parameters `params` for
    /// `model` (and a cascade's secondary `inner`) at the period `ts`; empty
    /// for a scheme whose parameters are all it designs.
    pub fn design_report(
        &self,
        params: &Params,
        model: &TransferFunction,
        inner: Option<&TransferFunction>,
        ts: f64,
    ) -> Result<DesignReport, crate::error::Error> {
        match self.describe {
            Some(f) => f(params, model, inner, ts),
            None => Ok(Vec::new()),
        }
    }

    /// True for a cascade scheme (it needs the secondary process).
    pub fn is_cascade(&self) -> bool {
        matches!(self.fns, SchemeFns::Cascade { .. })
    }

    /// Tunes on the primary `model` and, for a cascade process, the secondary
    /// `inner` model. A single-loop scheme on a cascade process controls the
    /// whole series `P1·P2` from the plant input (the secondary measurement unused).
    pub fn tune_process(
        &'static self,
        model: &TransferFunction,
        inner: Option<&TransferFunction>,
        lambda: Option<f64>,
        rule: Option<&str>,
        overrides: &[(String, f64)],
    ) -> Result<Params, RegistryError> {
        let whole;
        let model = match (inner, self.is_cascade()) {
            (Some(p2), false) => {
                whole = model.series(p2)?;
                &whole
            }
            _ => model,
        };
        // the order first: a model beyond the blocks' capacity says so,
        // whatever else is wrong with it
        if model.model_order() > MAX_ORDER {
            return Err(crate::error::Error::OrderTooHigh("model").into());
        }
        model.check_controllable()?;
        if let Some(p2) = inner {
            p2.check_controllable()?;
        }
        // a named rule is for the PID schemes; elsewhere it would be ignored
        if rule.is_some() && !matches!(self.name, "pid" | "pi") {
            return Err(RegistryError::Core(crate::error::Error::Unsupported(
                "--rule (rule=) names a PID tuning rule: only the pid and pi schemes have them; tune the others with --lambda or --set",
            )));
        }
        // every parameter given: the user's controller is run as given (the
        // stability verdict says whether the loop holds), the tuning only
        // fills the parameter set on a stable stand-in of the model
        let stand_in;
        let all_given = !self.params.is_empty()
            && self
                .params
                .iter()
                .all(|p| overrides.iter().any(|(k, _)| k == p));
        let model = if !self.plants.contains(&model.kind()) && all_given && !self.is_cascade() {
            stand_in = model.stable_stand_in()?;
            &stand_in
        } else {
            model
        };
        let kind = model.kind();
        if !self.plants.contains(&kind) {
            return Err(RegistryError::PlantKind {
                scheme: self.name,
                kind,
                alternatives: SCHEMES
                    .iter()
                    .filter(|s| s.plants.contains(&kind))
                    .map(|s| s.name)
                    .collect(),
            });
        }
        let design = Design {
            lambda,
            rule: rule.map(ToString::to_string),
            values: overrides
                .iter()
                .filter(|(k, _)| self.design.contains(&k.as_str()))
                .cloned()
                .collect(),
        };
        let mut params = match (self.fns, inner) {
            (SchemeFns::Cascade { tune, .. }, Some(p2)) => tune(model, p2, &design)?,
            (SchemeFns::Cascade { .. }, None) => return Err(needs_inner()),
            (SchemeFns::Single { tune, .. }, _) => tune(model, &design)?,
        };
        for (k, v) in overrides {
            if self.design.contains(&k.as_str()) {
                continue;
            }
            if !params.set(k, *v) {
                let mut allowed: Vec<&'static str> = self.params.to_vec();
                allowed.extend(self.design.iter().filter(|d| !self.params.contains(d)));
                return Err(RegistryError::UnknownParam {
                    scheme: self.name,
                    name: k.clone(),
                    allowed,
                });
            }
        }
        // every parameter given: neither λ nor a rule made them
        Ok(if all_given { params.as_given() } else { params })
    }

    /// Builds the controller.
    pub fn build_with(
        &self,
        params: &Params,
        model: &TransferFunction,
        b: &Build,
    ) -> Result<DynController, RegistryError> {
        self.build_process(params, model, None, b)
    }

    /// Builds the controller for the primary `model` and, for a cascade
    /// process, the secondary `inner` model.
    pub fn build_process(
        &self,
        params: &Params,
        model: &TransferFunction,
        inner: Option<&TransferFunction>,
        b: &Build,
    ) -> Result<DynController, RegistryError> {
        self.build_process_as::<f64>(params, model, inner, b)
    }

    /// [`Scheme::build_process`] in precision `T` (`f32` for a controller that
    /// computes as firmware does; the design and discretization run in `f64`).
    pub fn build_process_as<T: Precision>(
        &self,
        params: &Params,
        model: &TransferFunction,
        inner: Option<&TransferFunction>,
        b: &Build,
    ) -> Result<DynControllerOf<T>, RegistryError> {
        Ok(match (self.fns, inner) {
            (SchemeFns::Cascade { build, .. }, Some(p2)) => {
                T::cascade(&build)(params, model, p2, b)?
            }
            (SchemeFns::Cascade { .. }, None) => return Err(needs_inner()),
            (SchemeFns::Single { build, .. }, Some(p2)) => {
                T::single(&build)(params, &model.series(p2)?, b)?
            }
            (SchemeFns::Single { build, .. }, None) => T::single(&build)(params, model, b)?,
        })
    }
}
