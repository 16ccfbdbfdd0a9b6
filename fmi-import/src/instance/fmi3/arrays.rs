//! The FMI 3.0 view of an instance: a variable that is no plain scalar (an array element,
//! another FMI 3.0 type, a 64-bit integer kept exact) read and set through its own
//! getters and setters, an array element set alone with the array's other elements as
//! set before.

use super::*;

impl Fmi3 {
    /// The access of the view's variable `vr` when it is not a plain scalar.
    #[inline]
    pub(super) fn special(&self, vr: u32) -> Option<Access> {
        if self.a.special.is_empty() {
            return None;
        }
        self.a.special.get(&vr).copied()
    }

    /// Whether some of `vrs` are not plain scalars: they go one by one.
    #[inline]
    pub(super) fn any_special(&self, vrs: &[u32]) -> bool {
        !self.a.special.is_empty() && vrs.iter().any(|vr| self.a.special.contains_key(vr))
    }

    /// The number of elements `access`'s variable has now, and which of them `access` is
    /// (`None`: an element the array does not have now): the view's unless a structural
    /// parameter sizes the array otherwise now.
    #[inline]
    pub(super) fn now(&self, access: Access) -> (usize, Option<usize>) {
        if self.resized.is_empty() {
            return (access.count, Some(access.element));
        }
        match self.resized.get(&access.vr) {
            None => (access.count, Some(access.element)),
            Some((view, dims)) => {
                (dims.iter().product::<u64>() as usize, crate::structural::element_now(view, dims, access.element))
            }
        }
    }

    /// The structural parameters have the values `now` (value reference, value) where they
    /// are not the view's: the arrays they size are read and set with their sizes now.
    pub(in crate::instance) fn resize(&mut self, now: Vec<(u32, f64)>) {
        self.resized = crate::structural::resized_arrays(&self.a.description, &now);
        self.sizes_now = now;
        let resized = &self.resized;
        self.arrays.retain(|vr, _| !resized.contains_key(vr));
        self.wide_arrays.retain(|vr, _| !resized.contains_key(vr));
    }

    /// All values of the FMI 3.0 variable of `access` (as many as it has now), as f64
    /// (64-bit integers the nearest, exact up to 2^53; Booleans 0 or 1, a Binary its size in
    /// bytes).
    pub(super) fn get_all(&mut self, core: &mut Core, access: Access) -> Result<Vec<f64>> {
        use model_description::fmi3::ValueType as T;
        let n = self.now(access).0;
        let c = core.component;
        let a = &*self.a;
        let vr = access.vr;
        macro_rules! get {
            ($field:ident, $name:literal, $t:ty) => {{
                let f = f3!(core, a, $field, $name);
                let mut buf: Vec<$t> = vec![<$t>::default(); n];
                call!(core, $name, None, f(c, &vr, 1, buf.as_mut_ptr(), n))?;
                buf
            }};
        }
        Ok(match access.value_type {
            T::Float64 => {
                let f = a.functions.get_float64;
                let mut buf = vec![0.0; n];
                call!(core, "fmi3GetFloat64", None, f(c, &vr, 1, buf.as_mut_ptr(), n))?;
                buf
            }
            T::Float32 => get!(get_float32, "fmi3GetFloat32", f32).into_iter().map(f64::from).collect(),
            T::Int8 => get!(get_int8, "fmi3GetInt8", i8).into_iter().map(f64::from).collect(),
            T::UInt8 => get!(get_uint8, "fmi3GetUInt8", u8).into_iter().map(f64::from).collect(),
            T::Int16 => get!(get_int16, "fmi3GetInt16", i16).into_iter().map(f64::from).collect(),
            T::UInt16 => get!(get_uint16, "fmi3GetUInt16", u16).into_iter().map(f64::from).collect(),
            T::Int32 => get!(get_int32, "fmi3GetInt32", i32).into_iter().map(f64::from).collect(),
            T::UInt32 => get!(get_uint32, "fmi3GetUInt32", u32).into_iter().map(f64::from).collect(),
            // the nearest f64 (exact up to 2^53); `get_exact` reads the integer itself
            T::Int64 | T::Enumeration => get!(get_int64, "fmi3GetInt64", i64).into_iter().map(|x| x as f64).collect(),
            T::UInt64 => get!(get_uint64, "fmi3GetUInt64", u64).into_iter().map(|x| x as f64).collect(),
            T::Boolean => get!(get_boolean, "fmi3GetBoolean", u8).into_iter().map(|b| (b != 0) as i32 as f64).collect(),
            T::Binary => {
                let f = f3!(core, a, get_binary, "fmi3GetBinary");
                let mut sizes = vec![0usize; n];
                let mut data: Vec<*const u8> = vec![std::ptr::null(); n];
                call!(core, "fmi3GetBinary", None, f(c, &vr, 1, sizes.as_mut_ptr(), data.as_mut_ptr(), n))?;
                sizes.into_iter().map(|s| s as f64).collect()
            }
            T::String | T::Clock => unreachable!("not in the view as a number"),
        })
    }

    /// All values of the Int64, UInt64 or Binary variable of `access` (as many as it has
    /// now) as the FMU holds them.
    pub(super) fn exact_all(&mut self, core: &mut Core, access: Access) -> Result<Vec<crate::fmi3::Exact>> {
        use crate::fmi3::Exact;
        use model_description::fmi3::ValueType as T;
        let n = self.now(access).0;
        let (c, a, vr) = (core.component, &*self.a, access.vr);
        Ok(match access.value_type {
            T::Int64 => {
                let f = f3!(core, a, get_int64, "fmi3GetInt64");
                let mut buf = vec![0i64; n];
                call!(core, "fmi3GetInt64", None, f(c, &vr, 1, buf.as_mut_ptr(), n))?;
                buf.into_iter().map(|x| Exact::Integer(i128::from(x))).collect()
            }
            T::UInt64 => {
                let f = f3!(core, a, get_uint64, "fmi3GetUInt64");
                let mut buf = vec![0u64; n];
                call!(core, "fmi3GetUInt64", None, f(c, &vr, 1, buf.as_mut_ptr(), n))?;
                buf.into_iter().map(|x| Exact::Integer(i128::from(x))).collect()
            }
            T::Binary => {
                let f = f3!(core, a, get_binary, "fmi3GetBinary");
                let mut sizes = vec![0usize; n];
                let mut data: Vec<*const u8> = vec![std::ptr::null(); n];
                call!(core, "fmi3GetBinary", None, f(c, &vr, 1, sizes.as_mut_ptr(), data.as_mut_ptr(), n))?;
                let bytes = |(p, size): (*const u8, usize)| match p.is_null() || size == 0 {
                    true => Exact::Bytes(Vec::new()),
                    // SAFETY: the FMU returned `size` bytes at `p`, valid until its next call.
                    false => Exact::Bytes(unsafe { std::slice::from_raw_parts(p, size) }.to_vec()),
                };
                data.into_iter().zip(sizes).map(bytes).collect()
            }
            _ => return Err(not_exact(core, access.vr, String::new())),
        })
    }

    /// Element `access` within one get call, whose last array read is `array`: an array is
    /// read once per call, not once per element (the elements of one array are asked
    /// together, a row of the results, and the FMU does not change in between), so that
    /// a row costs time linear in the elements.
    pub(super) fn element_of_call(
        &mut self,
        core: &mut Core,
        access: Access,
        array: &mut Option<(u32, Vec<f64>)>,
    ) -> Result<f64> {
        if access.count <= 1 {
            return self.get_element(core, access);
        }
        if array.as_ref().is_none_or(|(read, _)| *read != access.vr) {
            *array = Some((access.vr, self.get_all(core, access)?));
        }
        let element = self.now(access).1;
        Ok(array.as_ref().zip(element).and_then(|((_, all), k)| all.get(k)).copied().unwrap_or(f64::NAN))
    }

    /// One element; NaN for one its array does not have now.
    pub(super) fn get_element(&mut self, core: &mut Core, access: Access) -> Result<f64> {
        let all = self.get_all(core, access)?;
        Ok(self.now(access).1.and_then(|k| all.get(k)).copied().unwrap_or(f64::NAN))
    }

    /// Sets all values of the FMI 3.0 variable of `access` from f64 (integers must be
    /// whole and in their type's range).
    pub(in crate::instance) fn set_all(&mut self, core: &mut Core, access: Access, values: &[f64]) -> Result<()> {
        use model_description::fmi3::ValueType as T;
        let c = core.component;
        let name = core
            .fmu
            .description
            .model_variables
            .iter()
            .find(|v| v.value_reference == access.vr)
            .map(|v| v.name.clone());
        let a = &*self.a;
        let (vr, n) = (access.vr, values.len());
        let instance = core.name.clone();
        let variable = || format!("{instance}.{}", name.clone().unwrap_or_else(|| format!("<vr {vr}>")));
        macro_rules! set_int {
            ($field:ident, $name:literal, $t:ty) => {{
                let f = f3!(core, a, $field, $name);
                let mut buf: Vec<$t> = Vec::with_capacity(n);
                for x in values {
                    let wide = *x as i128;
                    let fits = wide as f64 == *x && wide >= <$t>::MIN as i128 && wide <= <$t>::MAX as i128;
                    if !fits {
                        return Err(Error::InvalidValue {
                            variable: variable(),
                            value: x.to_string(),
                            reason: format!("not a whole number of {}", stringify!($t)),
                        });
                    }
                    buf.push(wide as $t);
                }
                call!(core, $name, None, f(c, &vr, 1, buf.as_ptr(), n))
            }};
        }
        match access.value_type {
            T::Float64 => {
                let f = a.functions.set_float64;
                call!(core, "fmi3SetFloat64", None, f(c, &vr, 1, values.as_ptr(), n))
            }
            T::Float32 => {
                let f = f3!(core, a, set_float32, "fmi3SetFloat32");
                let buf: Vec<f32> = values.iter().map(|x| *x as f32).collect();
                call!(core, "fmi3SetFloat32", None, f(c, &vr, 1, buf.as_ptr(), n))
            }
            T::Int8 => set_int!(set_int8, "fmi3SetInt8", i8),
            T::UInt8 => set_int!(set_uint8, "fmi3SetUInt8", u8),
            T::Int16 => set_int!(set_int16, "fmi3SetInt16", i16),
            T::UInt16 => set_int!(set_uint16, "fmi3SetUInt16", u16),
            T::Int32 => set_int!(set_int32, "fmi3SetInt32", i32),
            T::UInt32 => set_int!(set_uint32, "fmi3SetUInt32", u32),
            T::Int64 | T::Enumeration => set_int!(set_int64, "fmi3SetInt64", i64),
            T::UInt64 => set_int!(set_uint64, "fmi3SetUInt64", u64),
            T::Boolean => {
                let f = f3!(core, a, set_boolean, "fmi3SetBoolean");
                let buf: Vec<u8> = values.iter().map(|x| (*x != 0.0) as u8).collect();
                call!(core, "fmi3SetBoolean", None, f(c, &vr, 1, buf.as_ptr(), n))
            }
            T::Binary | T::String | T::Clock => Err(Error::InvalidValue {
                variable: variable(),
                value: values.first().map(|x| x.to_string()).unwrap_or_default(),
                reason: "a Binary is recorded as its size and cannot be set".into(),
            }),
        }
    }

    /// Sets element `access.element` of its variable: the other elements keep the values
    /// set or read before (the start values at first).
    pub(super) fn set_element(&mut self, core: &mut Core, access: Access, value: f64) -> Result<()> {
        use model_description::fmi3::ValueType as T;
        if access.count == 1 {
            return self.set_all(core, access, &[value]);
        }
        // a 64-bit array keeps its elements as integers: set through the same values
        if matches!(access.value_type, T::Int64 | T::UInt64) {
            let whole = value as i128;
            if whole as f64 != value {
                let name = self.a.description.variable(access.vr).map_or("?", |v| v.name.as_str());
                return Err(Error::InvalidValue {
                    variable: format!("{}.{name}", core.name),
                    value: value.to_string(),
                    reason: format!("not a whole number of {:?}", access.value_type),
                });
            }
            return self.set_wide_element(core, access, whole);
        }
        self.set_kept_element(core, access, value, |a| &mut a.arrays, Fmi3::array_start, Fmi3::set_all)
    }

    /// Sets element `access.element` of an Int64 or UInt64 array to the integer `value`
    /// exactly: the other elements keep the integers set or read before (the start values
    /// at first).
    pub(super) fn set_wide_element(&mut self, core: &mut Core, access: Access, value: i128) -> Result<()> {
        self.set_kept_element(core, access, value, |a| &mut a.wide_arrays, Fmi3::wide_array_start, Fmi3::set_wide)
    }

    /// Sets element `access.element` of its variable to `value`: the other elements keep
    /// the values set or read before, kept in `kept` (f64, or i128 for the integers of a
    /// 64-bit array, which an f64 holds only up to 2^53), from `start` at first; the whole
    /// array is set with `set`.
    fn set_kept_element<T: Copy + ToString>(
        &mut self,
        core: &mut Core,
        access: Access,
        value: T,
        kept: fn(&mut Fmi3) -> &mut HashMap<u32, Vec<T>>,
        start: fn(&mut Fmi3, &mut Core, Access) -> Result<Vec<T>>,
        set: fn(&mut Fmi3, &mut Core, Access, &[T]) -> Result<()>,
    ) -> Result<()> {
        let (n, element) = self.now(access);
        let Some(element) = element else {
            return Err(self.absent_element(core, access, n, value.to_string()));
        };
        let mut values = match kept(self).remove(&access.vr) {
            Some(v) if v.len() == n => v,
            _ => start(self, core, access)?,
        };
        values[element] = value;
        let result = set(self, core, access, &values);
        kept(self).insert(access.vr, values);
        result
    }

    /// The error of a set of an element the array does not have now (`n` elements).
    pub(super) fn absent_element(&self, core: &Core, access: Access, n: usize, value: String) -> Error {
        let name = self.a.description.variable(access.vr).map_or("?", |v| v.name.as_str());
        Error::InvalidValue {
            variable: format!("{}.{name}", core.name),
            value,
            reason: format!(
                "element {} of an array that has {n} elements now (a structural parameter sized it so)",
                access.element + 1
            ),
        }
    }

    /// The integers a 64-bit array starts from for element-wise sets: its start values,
    /// else what the FMU holds.
    pub(super) fn wide_array_start(&mut self, core: &mut Core, access: Access) -> Result<Vec<i128>> {
        use model_description::fmi3::{ValueType as T, Values};
        let n = self.now(access).0;
        if !self.resized.contains_key(&access.vr) {
            if let Some(Values::Int(v)) = self.a.description.variable(access.vr).and_then(|v| v.start.clone()) {
                if v.len() == n {
                    return Ok(v);
                }
                if v.len() == 1 {
                    return Ok(vec![v[0]; n]);
                }
            }
        }
        let (c, a, vr) = (core.component, &*self.a, access.vr);
        Ok(if access.value_type == T::UInt64 {
            let f = f3!(core, a, get_uint64, "fmi3GetUInt64");
            let mut buf = vec![0u64; n];
            call!(core, "fmi3GetUInt64", None, f(c, &vr, 1, buf.as_mut_ptr(), n))?;
            buf.into_iter().map(i128::from).collect()
        } else {
            let f = f3!(core, a, get_int64, "fmi3GetInt64");
            let mut buf = vec![0i64; n];
            call!(core, "fmi3GetInt64", None, f(c, &vr, 1, buf.as_mut_ptr(), n))?;
            buf.into_iter().map(i128::from).collect()
        })
    }

    /// Sets all values of the Int64 or UInt64 variable of `access` to the integers
    /// `values`, each checked against the type's range (an error names the variable).
    pub(super) fn set_wide(&mut self, core: &mut Core, access: Access, values: &[i128]) -> Result<()> {
        use model_description::fmi3::ValueType as T;
        let (c, vr, n) = (core.component, access.vr, values.len());
        if access.value_type == T::Int64 {
            let buf: Vec<i64> = self.narrowed(core, vr, values, "Int64")?;
            let f = f3!(core, self.a, set_int64, "fmi3SetInt64");
            call!(core, "fmi3SetInt64", None, f(c, &vr, 1, buf.as_ptr(), n))
        } else {
            let buf: Vec<u64> = self.narrowed(core, vr, values, "UInt64")?;
            let f = f3!(core, self.a, set_uint64, "fmi3SetUInt64");
            call!(core, "fmi3SetUInt64", None, f(c, &vr, 1, buf.as_ptr(), n))
        }
    }

    /// `values` as the 64-bit integers of type `T` (FMI 3.0's `type_name`) of the variable
    /// `vr`, or the error that names the variable and the first value outside T's range.
    fn narrowed<T: TryFrom<i128>>(&self, core: &Core, vr: u32, values: &[i128], type_name: &str) -> Result<Vec<T>> {
        values
            .iter()
            .map(|&x| {
                T::try_from(x).map_err(|_| {
                    // the FMU's own name of the variable (the view's element names are not its)
                    let name = self.a.description.variable(vr).map_or_else(|| format!("<vr {vr}>"), |v| v.name.clone());
                    Error::InvalidValue {
                        variable: format!("{}.{name}", core.name),
                        value: x.to_string(),
                        reason: format!("outside the range of {type_name}"),
                    }
                })
            })
            .collect()
    }

    /// The values an array starts from for element-wise sets: its start values, else what
    /// the FMU holds.
    pub(super) fn array_start(&mut self, core: &mut Core, access: Access) -> Result<Vec<f64>> {
        use model_description::fmi3::Values;
        // a resized array: what the FMU holds (its start values are the view's size)
        let start = match self.resized.contains_key(&access.vr) {
            true => None,
            false => self.a.description.variable(access.vr).and_then(|v| v.start.clone()),
        };
        let n = self.now(access).0;
        let spread = |v: Vec<f64>| if v.len() == 1 { vec![v[0]; n] } else { v };
        match start {
            Some(Values::Float(v)) if v.len() == n || v.len() == 1 => Ok(spread(v)),
            Some(Values::Int(v)) if v.len() == n || v.len() == 1 => {
                Ok(spread(v.into_iter().map(|x| x as f64).collect()))
            }
            Some(Values::Boolean(v)) if v.len() == n || v.len() == 1 => {
                Ok(spread(v.into_iter().map(|x| x as i32 as f64).collect()))
            }
            _ => self.get_all(core, access),
        }
    }
}
