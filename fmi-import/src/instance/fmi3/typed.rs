//! The FMI 3.0 typed getters and setters behind the instance's calls: the FMU's own calls
//! (through the view where a variable is special), and clocked variables' values held
//! between their ticks (read) and queued until their clock ticks (set).

use super::*;

impl Fmi3 {
    #[inline]
    pub(super) fn fmu_get_real(&mut self, core: &mut Core, vrs: &[u32], values: &mut [f64]) -> Result<()> {
        let (c, f) = (core.component, self.a.functions.get_float64);
        if !self.any_special(vrs) {
            return call!(
                core,
                "fmi3GetFloat64",
                None,
                f(c, vrs.as_ptr(), vrs.len(), values.as_mut_ptr(), values.len())
            );
        }
        let mut array = None;
        for (vr, value) in vrs.iter().zip(values.iter_mut()) {
            match self.special(*vr) {
                Some(access) => *value = self.element_of_call(core, access, &mut array)?,
                None => call!(core, "fmi3GetFloat64", None, f(c, vr, 1, value, 1))?,
            }
        }
        Ok(())
    }

    #[inline]
    pub(super) fn fmu_get_integer(&mut self, core: &mut Core, vrs: &[u32], values: &mut [i32]) -> Result<()> {
        let c = core.component;
        if !self.any_special(vrs) {
            let f = f3!(core, self.a, get_int32, "fmi3GetInt32");
            return call!(core, "fmi3GetInt32", None, f(c, vrs.as_ptr(), vrs.len(), values.as_mut_ptr(), values.len()));
        }
        let get32 = self.a.functions.get_int32;
        let mut array = None;
        for (vr, value) in vrs.iter().zip(values.iter_mut()) {
            match self.special(*vr) {
                Some(access) => {
                    let x = self.element_of_call(core, access, &mut array)?;
                    // the view's Integers are Int8 .. Int32 and Enumerations of i32 items
                    *value = i32::try_from(x as i64).map_err(|_| {
                        core.returned(
                            "fmi3GetInt64",
                            core.time,
                            format!(
                                "the value {x} of value reference {} is outside the range of the Integer (32 bits) \
                                 cosim reads it as",
                                access.vr
                            ),
                        )
                    })?;
                }
                None => {
                    let f = core.optional(get32, "fmi3GetInt32")?;
                    call!(core, "fmi3GetInt32", None, f(c, vr, 1, value, 1))?
                }
            }
        }
        Ok(())
    }

    #[inline]
    pub(super) fn fmu_get_boolean(&mut self, core: &mut Core, vrs: &[u32], values: &mut [i32]) -> Result<()> {
        if self.any_special(vrs) {
            let mut array = None;
            for (vr, value) in vrs.iter().zip(values.iter_mut()) {
                *value = match self.special(*vr) {
                    Some(access) => self.element_of_call(core, access, &mut array)? as i32,
                    None => {
                        let mut one = [0];
                        self.fmu_get_boolean(core, &[*vr], &mut one)?;
                        one[0]
                    }
                };
            }
            return Ok(());
        }
        let c = core.component;
        let f = f3!(core, self.a, get_boolean, "fmi3GetBoolean");
        let mut bytes = std::mem::take(&mut self.bytes);
        bytes.clear();
        bytes.resize(vrs.len(), 0);
        let r = call!(core, "fmi3GetBoolean", None, f(c, vrs.as_ptr(), vrs.len(), bytes.as_mut_ptr(), bytes.len()));
        for (v, b) in values.iter_mut().zip(&bytes) {
            *v = (*b != 0) as i32;
        }
        self.bytes = bytes;
        r
    }

    #[inline]
    pub(super) fn fmu_set_real(&mut self, core: &mut Core, vrs: &[u32], values: &[f64]) -> Result<()> {
        let (c, f) = (core.component, self.a.functions.set_float64);
        if !self.any_special(vrs) {
            return call!(core, "fmi3SetFloat64", None, f(c, vrs.as_ptr(), vrs.len(), values.as_ptr(), values.len()));
        }
        for (vr, value) in vrs.iter().zip(values) {
            match self.special(*vr) {
                Some(access) => self.set_element(core, access, *value)?,
                None => call!(core, "fmi3SetFloat64", None, f(c, vr, 1, value, 1))?,
            }
        }
        Ok(())
    }

    #[inline]
    pub(super) fn fmu_set_integer(&mut self, core: &mut Core, vrs: &[u32], values: &[i32]) -> Result<()> {
        let c = core.component;
        if !self.any_special(vrs) {
            let f = f3!(core, self.a, set_int32, "fmi3SetInt32");
            return call!(core, "fmi3SetInt32", None, f(c, vrs.as_ptr(), vrs.len(), values.as_ptr(), values.len()));
        }
        let set32 = self.a.functions.set_int32;
        for (vr, value) in vrs.iter().zip(values) {
            match self.special(*vr) {
                Some(access) => self.set_element(core, access, *value as f64)?,
                None => {
                    let f = core.optional(set32, "fmi3SetInt32")?;
                    call!(core, "fmi3SetInt32", None, f(c, vr, 1, value, 1))?
                }
            }
        }
        Ok(())
    }

    #[inline]
    pub(super) fn fmu_set_boolean(&mut self, core: &mut Core, vrs: &[u32], values: &[i32]) -> Result<()> {
        if self.any_special(vrs) {
            for (vr, value) in vrs.iter().zip(values) {
                match self.special(*vr) {
                    Some(access) => self.set_element(core, access, (*value != 0) as i32 as f64)?,
                    None => self.fmu_set_boolean(core, &[*vr], &[*value])?,
                }
            }
            return Ok(());
        }
        let c = core.component;
        let f = f3!(core, self.a, set_boolean, "fmi3SetBoolean");
        let mut bytes = std::mem::take(&mut self.bytes);
        bytes.clear();
        bytes.extend(values.iter().map(|v| (*v != 0) as u8));
        let r = call!(core, "fmi3SetBoolean", None, f(c, vrs.as_ptr(), vrs.len(), bytes.as_ptr(), bytes.len()));
        self.bytes = bytes;
        r
    }

    /// A get of the view's `vrs` on an FMU with clocked variables: while running, a
    /// clocked variable's value is the one held since its clocks' last activation (the
    /// FMU refuses the access outside it); the others are read from the FMU by `fmu_get`,
    /// in one call. In Initialization Mode everything is read, the clocked values kept as
    /// held.
    pub(super) fn get_held<T: HeldNumber>(
        &mut self,
        core: &mut Core,
        vrs: &[u32],
        values: &mut [T],
        fmu_get: fn(&mut Fmi3, &mut Core, &[u32], &mut [T]) -> Result<()>,
    ) -> Result<()> {
        let at = |me: &Fmi3, vr: u32| me.clocked.clocked(vr, me.special(vr));
        if !core.state.is_running() {
            fmu_get(self, core, vrs, values)?;
            for (vr, value) in vrs.iter().zip(values.iter()) {
                if let Some((slot, element)) = at(self, *vr) {
                    self.clocked.hold_element(slot, element, value.to_held());
                }
            }
            return Ok(());
        }
        // a clocked variable is answered from its held value unless one of its clocks is
        // active (then read, and held); the rest (no allocation when nothing is held: the
        // common case of a plain read, or of the reads in an open clock event)
        let held = |me: &Fmi3, vr: u32| {
            at(me, vr)
                .filter(|(slot, _)| !me.clocked.is_active(*slot))
                .and_then(|(slot, element)| me.clocked.held(slot, element))
        };
        if vrs.iter().all(|vr| held(self, *vr).is_none()) {
            fmu_get(self, core, vrs, values)?;
            self.hold_read(vrs, values);
            return Ok(());
        }
        let (mut free_vrs, mut free_at) = (Vec::new(), Vec::new());
        for (k, vr) in vrs.iter().enumerate() {
            match held(self, *vr) {
                Some(held) => values[k] = T::from_held(held),
                None => {
                    free_vrs.push(*vr);
                    free_at.push(k);
                }
            }
        }
        let mut free_values: Vec<T> = free_at.iter().map(|k| values[*k]).collect();
        fmu_get(self, core, &free_vrs, &mut free_values)?;
        self.hold_read(&free_vrs, &free_values);
        for (k, value) in free_at.into_iter().zip(free_values) {
            values[k] = value;
        }
        Ok(())
    }

    /// The clocked variables among `vrs` whose clocks are active, just read from or set
    /// to the FMU, held.
    pub(super) fn hold_read<T: HeldNumber>(&mut self, vrs: &[u32], values: &[T]) {
        if self.ticked_inputs.is_empty() {
            return;
        }
        for (vr, value) in vrs.iter().zip(values) {
            if let Some((slot, element)) = self.clocked.clocked(*vr, self.special(*vr)) {
                if self.clocked.is_active(slot) {
                    self.clocked.hold_element(slot, element, value.to_held());
                }
            }
        }
    }

    /// A set of the view's `vrs` on an FMU with clocked variables: while running, a set of
    /// a clocked input is queued to its clocks' next activation (the FMU refuses it
    /// outside one); the others are set by `fmu_set`, in one call. In Initialization Mode
    /// everything is set, the clocked values kept as held.
    pub(super) fn set_queued<T: HeldNumber>(
        &mut self,
        core: &mut Core,
        vrs: &[u32],
        values: &[T],
        fmu_set: fn(&mut Fmi3, &mut Core, &[u32], &[T]) -> Result<()>,
    ) -> Result<()> {
        let at = |me: &Fmi3, vr: u32| me.clocked.clocked(vr, me.special(vr));
        if !core.state.is_running() {
            fmu_set(self, core, vrs, values)?;
            for (vr, value) in vrs.iter().zip(values) {
                if let Some((slot, element)) = at(self, *vr) {
                    self.clocked.hold_element(slot, element, value.to_held());
                }
            }
            return Ok(());
        }
        // no settable clocked variable (a sampled controller's clocked outputs, say): nothing
        // to queue or hold, the set goes to the FMU without a lookup per value reference
        if !self.clocked.has_settable() {
            return fmu_set(self, core, vrs, values);
        }
        // a clocked input whose clocks are inactive is queued; every other variable set (a
        // clocked input of an active clock, in an open clock event, held too)
        let queued = |me: &Fmi3, vr: u32| {
            at(me, vr).filter(|(slot, _)| me.clocked.is_input(*slot) && !me.clocked.is_active(*slot))
        };
        if vrs.iter().all(|vr| queued(self, *vr).is_none()) {
            fmu_set(self, core, vrs, values)?;
            self.hold_read(vrs, values);
            return Ok(());
        }
        let (mut free_vrs, mut free_values) = (Vec::new(), Vec::new());
        for (vr, value) in vrs.iter().zip(values) {
            match queued(self, *vr) {
                Some((slot, element)) => self.clocked.queue(slot, element, value.to_held()),
                None => {
                    free_vrs.push(*vr);
                    free_values.push(*value);
                }
            }
        }
        if free_vrs.is_empty() {
            return Ok(());
        }
        fmu_set(self, core, &free_vrs, &free_values)?;
        self.hold_read(&free_vrs, &free_values);
        Ok(())
    }

    /// The queued sets of the clocked inputs of the clocks `active` applied (each as one
    /// set of the whole variable), the values held.
    pub(in crate::instance) fn apply_queued(&mut self, core: &mut Core, active: &[u32]) -> Result<()> {
        if self.clocked.is_empty() || active.is_empty() {
            return Ok(());
        }
        for (slot, access, values) in self.clocked.take_queued(active) {
            self.set_all(core, access, &values)?;
            self.clocked.hold(slot, values);
        }
        Ok(())
    }

    /// The clocked variables of the clocks `active` that the master reads (all but inputs)
    /// read and held until the next activation.
    pub(in crate::instance) fn read_clocked(&mut self, core: &mut Core, active: &[u32]) -> Result<()> {
        if self.clocked.is_empty() || active.is_empty() {
            return Ok(());
        }
        let mut plan = self.clocked.take_plan(active);
        let outcome = self.read_planned(core, &mut plan);
        self.clocked.put_plan(plan);
        outcome
    }

    pub(super) fn read_planned(
        &mut self,
        core: &mut Core,
        plan: &mut crate::instance::clocked::ReadPlan,
    ) -> Result<()> {
        if !plan.scalars.is_empty() {
            let (vrs, values) = (&plan.scalars, &mut plan.values);
            let (c, f) = (core.component, self.a.functions.get_float64);
            call!(core, "fmi3GetFloat64", None, f(c, vrs.as_ptr(), vrs.len(), values.as_mut_ptr(), values.len()))?;
            for (slot, value) in plan.scalar_slots.iter().zip(values.iter()) {
                self.clocked.hold_element(*slot, 0, *value);
            }
        }
        for (slot, access) in plan.others.iter() {
            let values = self.get_all(core, *access)?;
            self.clocked.hold(*slot, values);
        }
        Ok(())
    }

    /// In Event Mode at `time`: which output clocks ticked (`fmi3GetClock`) and the
    /// intervals of the input clocks the FMU gives (`fmi3GetIntervalDecimal`), kept for
    /// `take_output_ticks` and `take_intervals`.
    pub(super) fn read_output_clocks(&mut self, core: &mut Core, time: f64) -> Result<()> {
        let fixed = if self.fixed_read { &[][..] } else { &self.fixed_clocks[..] };
        if !self.interval_clocks.is_empty() || !fixed.is_empty() {
            let vrs: Vec<u32> = self.interval_clocks.iter().chain(fixed).copied().collect();
            self.fixed_read = true;
            let intervals = crate::instance::core::ClockCalls::get_intervals(self, core, &vrs, false)?;
            self.intervals.extend(vrs.into_iter().zip(intervals).map(|(vr, i)| (time, vr, i)));
        }
        if self.output_clocks.is_empty() {
            // (the list's buffer kept for the next event)
            let mut active = std::mem::take(&mut self.ticked_inputs);
            self.clocked.deactivate();
            let outcome = self.read_clocked(core, &active);
            active.clear();
            self.ticked_inputs = active;
            return outcome;
        }
        let vrs = self.output_clocks.clone();
        let mut ticks = vec![false; vrs.len()];
        ClockCalls::get_clocks(self, core, &vrs, &mut ticks)?;
        let opened = std::mem::take(&mut self.opened_outputs);
        let ticked: Vec<u32> =
            vrs.into_iter().zip(ticks).filter(|(vr, t)| *t && !opened.contains(vr)).map(|(vr, _)| vr).collect();
        for vr in &ticked {
            self.output_ticks.push(crate::instance::core::OutputTick { time, value_reference: *vr });
        }
        // the clocked variables of the clocks that ticked in this event, read as it settled
        let mut active = std::mem::take(&mut self.ticked_inputs);
        self.clocked.deactivate();
        active.extend(opened);
        active.extend(ticked);
        self.read_clocked(core, &active)
    }
}
