//! Each variable declared once: [`Variables`] collects the [`VarDecl`]s of a model and
//! assigns their value references; [`Field`] is the binding that reads and writes the
//! model's own field through a function pointer.
//!
//! ```text
//! let beta = v.real("beta").input(0.0).unit("rad").field(|m: &mut Controller, _| &mut m.inputs.beta);
//! let delta_ff = v.family("delta_ff", &WHEELS, |d, _| d.input(0.0).unit("rad")).field(|m, i| &mut m.inputs.delta_ff[i]);
//! v.family("delta", &WHEELS, |d, i| d.discrete_output([beta, delta_ff[i]])).field(|m, i| &mut m.held.delta[i]);
//! ```
//!
//! Why a builder with function pointers and not a derive macro over the model struct (as
//! rust-fmi does): the variables of our models are nested fields of structs that belong to
//! other crates (`m.inputs.delta_ff[i]` of a `nigel_benchmark::ControllerInputs`), families
//! whose names are built (`delta_ff_fl .. delta_ff_rr`), values computed on reading (the
//! gain in use) and enumerations kept as Rust enums; an attribute on a field can say none
//! of that without a second table, and a proc-macro crate costs a build step of its own.
//! A non-capturing closure `|m, i| &mut m.inputs.delta_ff[i]` is a plain `fn` pointer: a
//! get or set is one indirect call (about 1 ns), with no allocation and no hashing.
//!
//! Value references: per base type, in declaration order from 0, so that appending a
//! variable keeps every earlier one. Each FMU pins them in a checked-in table
//! ([`crate::Declaration::check_pinned_value_references`]) compared by a test, so that a change shows in
//! review. Dependencies (the ModelStructure) are given by the [`VarHandle`]s the builder
//! returned, never by numbers or by repeating names.

use crate::decl::{declared_name, BaseType, Causality, Dependencies, VarDecl, VarHandle};
use crate::model::{Access, Model, ModelResult};

/// The variables of a model, in declaration order, with their value references assigned.
#[derive(Debug)]
pub struct Variables<B> {
    declared: Vec<VarDecl<B>>,
    next: [u32; 3],
}

impl<B> Default for Variables<B> {
    fn default() -> Self {
        Variables { declared: Vec::new(), next: [0; 3] }
    }
}

/// A variable being declared: the builder chain of [`VarDecl`] applies, and a binding
/// method (`field`, `computed`, `get_set`, `bind`) ends it.
pub struct Pending<'a, B> {
    variables: &'a mut Variables<B>,
    index: usize,
}

impl<B> std::fmt::Debug for Pending<'_, B> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Pending")
    }
}

/// A family of variables being declared (`{stem}_{suffix}` for each suffix); ends like
/// [`Pending`], the binding getting the member's index.
pub struct Family<'a, B> {
    variables: &'a mut Variables<B>,
    members: Vec<VarDecl<()>>,
}

fn slot(base_type: BaseType) -> usize {
    match base_type {
        BaseType::Real => 0,
        BaseType::Integer => 1,
        BaseType::Boolean => 2,
    }
}

impl<B> Variables<B> {
    pub fn new() -> Self {
        Self::default()
    }

    fn next_reference(&mut self, base_type: BaseType) -> u32 {
        let vr = &mut self.next[slot(base_type)];
        *vr += 1;
        *vr - 1
    }

    fn begin(&mut self, name: &'static str, base_type: BaseType) -> VarDecl<Pending<'_, B>> {
        let vr = self.next_reference(base_type);
        VarDecl::unbound(name, vr, base_type, Pending { variables: self, index: 0 })
    }

    /// A Real variable.
    pub fn real(&mut self, name: &'static str) -> VarDecl<Pending<'_, B>> {
        self.begin(name, BaseType::Real)
    }

    /// An Integer variable.
    pub fn integer(&mut self, name: &'static str) -> VarDecl<Pending<'_, B>> {
        self.begin(name, BaseType::Integer)
    }

    /// A Boolean variable.
    pub fn boolean(&mut self, name: &'static str) -> VarDecl<Pending<'_, B>> {
        self.begin(name, BaseType::Boolean)
    }

    /// An Enumeration of the type `type_name` (an Integer for the C API).
    pub fn enumeration(&mut self, name: &'static str, type_name: &'static str) -> VarDecl<Pending<'_, B>> {
        let mut v = self.begin(name, BaseType::Integer);
        v.declared_type = Some(type_name);
        v
    }

    /// The Real variables `{stem}_{suffix}` for each of `suffixes` (the wheels, say), with
    /// consecutive value references; `build(variable, k)` applies the builder chain to
    /// member `k`, whose binding gets index `k`.
    pub fn family(
        &mut self,
        stem: &str,
        suffixes: &[&str],
        build: impl Fn(VarDecl<()>, usize) -> VarDecl<()>,
    ) -> Family<'_, B> {
        self.family_columns(&[stem], suffixes, |d, k, _| build(d, k))
    }

    /// A matrix of Real variables stored row-major, a row per suffix and a column per stem
    /// (a gain with a row per wheel): for each suffix `i`, for each stem `j`, the variable
    /// `{stems[j]}_{suffixes[i]}` at index `k = stems.len() i + j` of the family (its
    /// binding's index), built by `build(variable, i, j)`.
    pub fn family_columns(
        &mut self,
        stems: &[&str],
        suffixes: &[&str],
        build: impl Fn(VarDecl<()>, usize, usize) -> VarDecl<()>,
    ) -> Family<'_, B> {
        let mut members = Vec::with_capacity(stems.len() * suffixes.len());
        for (i, suffix) in suffixes.iter().enumerate() {
            for (j, stem) in stems.iter().enumerate() {
                let vr = self.next_reference(BaseType::Real);
                let name = declared_name(format!("{stem}_{suffix}"));
                members.push(build(VarDecl::unbound(name, vr, BaseType::Real, ()), i, j));
            }
        }
        Family { variables: self, members }
    }

    /// Sets what `unknown` depends on after the fact (for a dependency on a variable
    /// declared after it).
    pub fn set_dependencies(&mut self, unknown: VarHandle, on: impl Into<Dependencies>) {
        if let Some(v) = self
            .declared
            .iter_mut()
            .find(|v| v.base_type == unknown.base_type && v.value_reference == unknown.value_reference)
        {
            v.dependencies = on.into();
        }
    }

    /// The declared variables, for [`crate::DeclarationSpec::variables`].
    pub fn into_vec(self) -> Vec<VarDecl<B>> {
        self.declared
    }

    fn push(&mut self, v: VarDecl<B>) -> VarHandle {
        let handle = VarHandle { base_type: v.base_type, value_reference: v.value_reference };
        self.declared.push(v);
        handle
    }
}

impl<'a, B> VarDecl<Pending<'a, B>> {
    /// The index the accessor gets (0 unless set): for a variable kept in an array, so that
    /// one accessor `|m, k| &mut m.values[k]` serves a table of variables.
    pub fn at(mut self, index: usize) -> Self {
        self.binding.index = index;
        self
    }

    /// Ends the declaration with the model's own binding (a model that dispatches itself).
    pub fn bind(self, binding: B) -> VarHandle {
        let (v, pending) = self.with_binding(binding);
        pending.variables.push(v)
    }
}

impl<'a, B> Family<'a, B> {
    /// Ends the family with the model's own bindings, `binding(k)` for member `k`.
    pub fn bind(self, binding: impl Fn(usize) -> B) -> Vec<VarHandle> {
        let Family { variables, members } = self;
        members
            .into_iter()
            .enumerate()
            .map(|(k, v)| {
                let (v, ()) = v.with_binding(binding(k));
                variables.push(v)
            })
            .collect()
    }
}

/// A value type a model field can have: `f64` for a Real, `i32` for an Integer or an
/// Enumeration, `bool` for a Boolean.
pub trait FieldValue: Copy + 'static {
    const BASE_TYPE: BaseType;
    #[doc(hidden)]
    fn field<M>(f: fn(&mut M, usize) -> &mut Self) -> Accessor<M>;
    #[doc(hidden)]
    fn get_set<M>(get: fn(&M, usize) -> Self, set: fn(&mut M, usize, Self) -> ModelResult) -> Accessor<M>;
}

/// `FieldValue` for each value type: its base type and its two [`Accessor`] variants.
macro_rules! field_values {
    ($($value:ty: $base_type:ident, $field:ident, $get_set:ident;)*) => {$(
        impl FieldValue for $value {
            const BASE_TYPE: BaseType = BaseType::$base_type;
            fn field<M>(f: fn(&mut M, usize) -> &mut $value) -> Accessor<M> {
                Accessor::$field(f)
            }
            fn get_set<M>(get: fn(&M, usize) -> $value, set: fn(&mut M, usize, $value) -> ModelResult) -> Accessor<M> {
                Accessor::$get_set(get, set)
            }
        }
    )*};
}

field_values! {
    f64: Real, Real, RealGetSet;
    i32: Integer, Integer, IntegerGetSet;
    bool: Boolean, Boolean, BooleanGetSet;
}

/// How a [`Field`] reaches its value. Every function gets the model and the variable's
/// index in its family (0 for a single variable).
pub enum Accessor<M> {
    /// A Real field, read and written in place (no check beyond the declaration's).
    Real(fn(&mut M, usize) -> &mut f64),
    Integer(fn(&mut M, usize) -> &mut i32),
    Boolean(fn(&mut M, usize) -> &mut bool),
    /// A value computed on reading (a calculated parameter, an output); not settable.
    RealComputed(fn(&M, usize) -> f64),
    /// A getter and a setter that checks what the declaration cannot say (and may refuse).
    RealGetSet(fn(&M, usize) -> f64, fn(&mut M, usize, f64) -> ModelResult),
    IntegerGetSet(fn(&M, usize) -> i32, fn(&mut M, usize, i32) -> ModelResult),
    BooleanGetSet(fn(&M, usize) -> bool, fn(&mut M, usize, bool) -> ModelResult),
}

impl<M> Clone for Accessor<M> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<M> Copy for Accessor<M> {}

/// The binding of a variable declared with [`Variables`]: the accessor, the variable's
/// index in its family, and whether setting it calls [`Model::parameters_changed`].
pub struct Field<M> {
    accessor: Accessor<M>,
    index: usize,
    parameter: bool,
}

impl<M> Clone for Field<M> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<M> Copy for Field<M> {}

impl<M> std::fmt::Debug for Field<M> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let kind = match self.accessor {
            Accessor::Real(_) => "Real field",
            Accessor::Integer(_) => "Integer field",
            Accessor::Boolean(_) => "Boolean field",
            Accessor::RealComputed(_) => "computed Real",
            Accessor::RealGetSet(..) => "Real get/set",
            Accessor::IntegerGetSet(..) => "Integer get/set",
            Accessor::BooleanGetSet(..) => "Boolean get/set",
        };
        write!(f, "{kind} [{}]", self.index)
    }
}

const NOT_SETTABLE: &str = "a calculated variable, not settable";

/// A field's getter and setter of Integers or Booleans (no computed ones): the accessor
/// variants of the type and the refusal for a variable of another type.
macro_rules! discrete_access {
    ($($get:ident, $set:ident: $value:ty, $field:ident, $get_set:ident, $other:literal;)*) => {$(
        fn $get(self, m: &mut M) -> ModelResult<$value> {
            match self.accessor {
                Accessor::$field(f) => Ok(*f(m, self.index)),
                Accessor::$get_set(get, _) => Ok(get(m, self.index)),
                _ => Err($other.into()),
            }
        }

        fn $set(self, m: &mut M, value: $value) -> ModelResult {
            match self.accessor {
                Accessor::$field(f) => *f(m, self.index) = value,
                Accessor::$get_set(_, set) => set(m, self.index, value)?,
                _ => return Err($other.into()),
            }
            if self.parameter {
                m.parameters_changed();
            }
            Ok(())
        }
    )*};
}

impl<M: Model> Access<M> for Field<M> {
    #[inline(always)]
    fn get_real(self, m: &mut M) -> ModelResult<f64> {
        match self.accessor {
            Accessor::Real(f) => Ok(*f(m, self.index)),
            Accessor::RealComputed(get) | Accessor::RealGetSet(get, _) => Ok(get(m, self.index)),
            _ => Err("not a Real".into()),
        }
    }

    #[inline(always)]
    fn set_real(self, m: &mut M, value: f64) -> ModelResult {
        match self.accessor {
            Accessor::Real(f) => *f(m, self.index) = value,
            Accessor::RealGetSet(_, set) => set(m, self.index, value)?,
            Accessor::RealComputed(_) => return Err(NOT_SETTABLE.into()),
            _ => return Err("not a Real".into()),
        }
        if self.parameter {
            m.parameters_changed();
        }
        Ok(())
    }

    discrete_access! {
        get_integer, set_integer: i32, Integer, IntegerGetSet, "not an Integer";
        get_boolean, set_boolean: bool, Boolean, BooleanGetSet, "not a Boolean";
    }

    /// A field takes every value the declaration lets through; a get/set pair may refuse.
    #[inline(always)]
    fn may_refuse(self) -> bool {
        !matches!(self.accessor, Accessor::Real(_) | Accessor::Integer(_) | Accessor::Boolean(_))
    }
}

fn field_of<M, B>(v: &VarDecl<B>, accessor: Accessor<M>, index: usize) -> Field<M> {
    Field { accessor, index, parameter: matches!(v.causality, Causality::Parameter) }
}

/// The declared base type must be the accessor's (a `bool` field for a Real is a slip the
/// declaration is refused for, when it is built).
fn checked<B>(v: VarDecl<B>, base_type: BaseType) -> VarDecl<B> {
    if v.base_type != base_type {
        let mut v = v;
        v.mismatched_accessor = true;
        return v;
    }
    v
}

impl<'a, M: Model> VarDecl<Pending<'a, Field<M>>> {
    /// Ends the declaration: the variable is the field `f(model, index)` returns (a Real
    /// `f64`, an Integer or Enumeration `i32`, a Boolean `bool`; the index is 0 unless
    /// [`VarDecl::at`] set it), read and written in place.
    pub fn field<T: FieldValue>(self, f: fn(&mut M, usize) -> &mut T) -> VarHandle {
        let v = checked(self, T::BASE_TYPE);
        let binding = field_of(&v, T::field(f), v.binding.index);
        v.bind(binding)
    }

    /// Ends the declaration of a value computed on reading (read-only: a calculated
    /// parameter or output).
    pub fn computed(self, get: fn(&M, usize) -> f64) -> VarHandle {
        let v = checked(self, BaseType::Real);
        let binding = field_of(&v, Accessor::RealComputed(get), v.binding.index);
        v.bind(binding)
    }

    /// Ends the declaration with a getter and a setter: for a value the model keeps in
    /// another form (an enum for an Integer), or a setter that checks what the declaration
    /// cannot say (the setter says why next to it). The setter may refuse: it then leaves
    /// the model unchanged.
    pub fn get_set<T: FieldValue>(
        self,
        get: fn(&M, usize) -> T,
        set: fn(&mut M, usize, T) -> ModelResult,
    ) -> VarHandle {
        let v = checked(self, T::BASE_TYPE);
        let binding = field_of(&v, T::get_set(get, set), v.binding.index);
        v.bind(binding)
    }
}

impl<'a, M: Model> Family<'a, Field<M>> {
    fn end(self, base_type: BaseType, accessor: Accessor<M>) -> Vec<VarHandle> {
        let Family { variables, members } = self;
        members
            .into_iter()
            .enumerate()
            .map(|(k, v)| {
                let v = checked(v, base_type);
                let binding = field_of(&v, accessor, k);
                let (v, ()) = v.with_binding(binding);
                variables.push(v)
            })
            .collect()
    }

    /// Ends the family: member `k` is the field `f(model, k)`.
    pub fn field(self, f: fn(&mut M, usize) -> &mut f64) -> Vec<VarHandle> {
        self.end(BaseType::Real, Accessor::Real(f))
    }

    /// Ends the family of values computed on reading: member `k` is `get(model, k)`.
    pub fn computed(self, get: fn(&M, usize) -> f64) -> Vec<VarHandle> {
        self.end(BaseType::Real, Accessor::RealComputed(get))
    }

    /// Ends the family with a getter and a setter (see [`VarDecl::get_set`]).
    pub fn get_set(self, get: fn(&M, usize) -> f64, set: fn(&mut M, usize, f64) -> ModelResult) -> Vec<VarHandle> {
        self.end(BaseType::Real, Accessor::RealGetSet(get, set))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decl::{Declaration, DeclarationSpec, Interfaces};
    use crate::model::{InstantiateContext, ModelError};

    #[derive(Clone, Debug, Default)]
    struct Toy {
        u: [f64; 2],
        gain: f64,
        mode: i32,
        on: bool,
        y: f64,
        changed: u32,
    }

    impl Model for Toy {
        type Binding = Field<Toy>;
        fn declaration() -> &'static Declaration<Field<Toy>> {
            unreachable!("the tests build their declarations")
        }
        fn instantiate(_: &InstantiateContext) -> ModelResult<Self> {
            Ok(Toy::default())
        }
        fn parameters_changed(&mut self) {
            self.changed += 1;
        }
    }

    fn declare() -> (Vec<VarDecl<Field<Toy>>>, Vec<VarHandle>) {
        let mut v = Variables::<Field<Toy>>::new();
        let u = v.family("u", &["a", "b"], |d, _| d.input(0.0)).field(|m, i| &mut m.u[i]);
        let mode = v.integer("mode").parameter(1).field(|m, _| &mut m.mode);
        let gain = v.real("gain").tunable_parameter(2.0).min(0.0).field(|m, _| &mut m.gain);
        let on = v.boolean("on").parameter(true).field(|m, _| &mut m.on);
        let twice = v.real("twice").calculated_parameter().computed(|m, _| 2.0 * m.gain);
        let y = v.real("y").discrete_output([u[1], u[0], u[1]]).get_set(
            |m, _| m.y,
            |m, _, x| {
                if x < 10.0 {
                    m.y = x;
                    Ok(())
                } else {
                    Err("y < 10".into())
                }
            },
        );
        let mut handles = u;
        handles.extend([mode, gain, on, twice, y]);
        (v.into_vec(), handles)
    }

    fn declaration(variables: Vec<VarDecl<Field<Toy>>>) -> Result<Declaration<Field<Toy>>, String> {
        Declaration::new(DeclarationSpec {
            model_name: "toy",
            model_identifier: "toy",
            interfaces: Interfaces { model_exchange: true, co_simulation: true },
            variables,
            ..Default::default()
        })
    }

    /// Value references count per base type from 0 in declaration order (a family takes
    /// consecutive ones), and the handles say the same.
    #[test]
    fn value_references_are_assigned_per_base_type_in_declaration_order() {
        let (variables, handles) = declare();
        let d = declaration(variables).unwrap();
        assert_eq!(d.value_reference_table(), "u_a 0 1\nu_b 1 2\nmode 0 3\ngain 2 4\non 0 5\ntwice 3 6\ny 4 7\n");
        let types = [BaseType::Real, BaseType::Real, BaseType::Integer, BaseType::Real, BaseType::Boolean];
        for (h, (v, t)) in handles.iter().zip(d.spec.variables.iter().zip(types)) {
            assert_eq!((h.base_type, h.value_reference), (t, v.value_reference), "{}", v.name);
        }
        // dependencies by handle: u_a and u_b (indices 1, 2), sorted and once each
        let y = d.model_description().model_structure.outputs.iter().find(|o| o.index == 7).unwrap();
        assert_eq!(y.dependencies, Some(vec![1, 2]));
    }

    /// Fields are read and written in place, a parameter's set calls the hook once, a
    /// computed value refuses a set, and a get/set pair's own check refuses and leaves the
    /// model unchanged.
    #[test]
    fn fields_read_and_write_the_model_and_call_the_hook_for_parameters() {
        let (variables, _) = declare();
        let b: Vec<Field<Toy>> = variables.iter().map(|v| v.binding).collect();
        let mut m = Toy::default();
        m.set_real(b[1], 0.5).unwrap();
        assert_eq!((m.u, m.changed), ([0.0, 0.5], 0), "an input is no parameter");
        m.set_real(b[3], 4.0).unwrap();
        assert_eq!((m.gain, m.changed, m.get_real(b[5]).unwrap()), (4.0, 1, 8.0));
        m.set_integer(b[2], 3).unwrap();
        m.set_boolean(b[4], true).unwrap();
        assert_eq!((m.mode, m.on, m.changed), (3, true, 3));
        assert_eq!(m.get_integer(b[2]), Ok(3));
        assert_eq!(m.get_boolean(b[4]), Ok(true));
        assert_eq!(m.set_real(b[5], 1.0), Err(ModelError::Error(NOT_SETTABLE.into())));
        m.set_real(b[6], 9.0).unwrap();
        assert!(m.set_real(b[6], 11.0).is_err());
        assert_eq!(m.get_real(b[6]), Ok(9.0));
        assert!(m.get_integer(b[0]).is_err() && m.set_boolean(b[3], true).is_err());
        // only the get/set pair and the computed value may refuse what the layer let through
        let may_refuse: Vec<bool> = b.iter().map(|&f| Toy::setter_may_refuse(f)).collect();
        assert_eq!(may_refuse, [false, false, false, false, false, true, true]);
    }

    /// A field of the wrong value type and a dependency on a non-Real are refused when the
    /// declaration is built, naming the variable.
    #[test]
    fn mismatched_accessors_and_dependencies_are_refused() {
        let mut v = Variables::<Field<Toy>>::new();
        v.real("flag").parameter(1.0).field(|m, _| &mut m.on);
        assert!(declaration(v.into_vec()).unwrap_err().contains("flag: the accessor's value type is not a Real"));
        let mut v = Variables::<Field<Toy>>::new();
        let mode = v.integer("mode").parameter(1).field(|m, _| &mut m.mode);
        v.real("y").discrete_output([mode]).field(|m, _| &mut m.y);
        assert!(declaration(v.into_vec()).unwrap_err().contains("y: dependency on a Integer, not a Real"));
    }
}
