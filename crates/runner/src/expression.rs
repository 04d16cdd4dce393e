//! Vector fields given in a scene file: each component a number or an expression in
//! x, y, z, t and the scene's `[definitions]`, parsed once with `exmex` (a maintained,
//! fast expression evaluator) and evaluated per particle.
//!
//! A definition is a named expression (`r = "sqrt(x^2 + y^2)"`) that other definitions
//! and fields use as a variable. Definitions are compiled once, ordered so each comes
//! after those it uses (a cycle is an error), and evaluated once per point before the
//! field's components: a long manufactured-solution body force stays readable and costs
//! each sub-expression once.

use std::collections::BTreeMap;

use exmex::prelude::*;
use nalgebra::SVector;

use crate::schema::Component;

/// The coordinates an expression may use, in slot order.
const VARIABLES: [&str; 4] = ["x", "y", "z", "t"];

/// Most definitions a scene may have: the values of one evaluation live on the stack.
pub const MAX_DEFINITIONS: usize = 60;

/// Names a definition may not take: the coordinates and exmex's constants.
const RESERVED: [&str; 6] = ["x", "y", "z", "t", "PI", "E"];

/// One compiled expression and, for each of its variables (exmex orders them
/// alphabetically), its slot in [x, y, z, t, definitions…].
#[derive(Debug, Clone)]
struct Compiled {
    /// Boxed: a flattened expression is large, constants are common.
    expr: Box<FlatEx<f64>>,
    slots: Vec<usize>,
}

impl Compiled {
    fn eval(&self, values: &[f64]) -> Result<f64, String> {
        // Most expressions read a few variables: a short array to gather them keeps
        // the evaluation from clearing and copying the whole slot range every time
        // (it was most of a manufactured body force's cost). Neither size allocates.
        if self.slots.len() <= 8 {
            self.eval_gathered::<8>(values)
        } else {
            self.eval_gathered::<{ 4 + MAX_DEFINITIONS }>(values)
        }
    }

    /// Evaluates with the variables gathered into an array of `N` ≥ the slot count.
    fn eval_gathered<const N: usize>(&self, values: &[f64]) -> Result<f64, String> {
        let mut arguments = [0.0; N];
        for (a, &s) in arguments.iter_mut().zip(&self.slots) {
            *a = values[s];
        }
        self.expr
            .eval(&arguments[..self.slots.len()])
            .map_err(|e| e.to_string())
    }
}

/// The scene's `[definitions]`, compiled and ordered.
#[derive(Debug, Clone, Default)]
pub struct Definitions {
    /// Names in evaluation order (slot 4 + i).
    names: Vec<String>,
    compiled: Vec<Compiled>,
}

/// Slots of `expr`'s variables among the coordinates (the first `coordinates` of them)
/// and the names in `known`, or the first unknown name.
fn slots(expr: &FlatEx<f64>, coordinates: usize, known: &[String]) -> Result<Vec<usize>, String> {
    expr.var_names()
        .iter()
        .map(|name| {
            VARIABLES[..coordinates]
                .iter()
                .position(|v| v == name)
                .or_else(|| known.iter().position(|k| k == name).map(|i| 4 + i))
                .ok_or_else(|| name.clone())
        })
        .collect()
}

impl Definitions {
    /// Compiles `definitions` (name → expression in x, y, z, t and other definitions).
    /// The error names the definition.
    pub fn compile(definitions: &BTreeMap<String, String>) -> Result<Self, (String, String)> {
        if definitions.len() > MAX_DEFINITIONS {
            return Err((
                String::new(),
                format!(
                    "{} definitions (at most {MAX_DEFINITIONS})",
                    definitions.len()
                ),
            ));
        }
        let mut parsed = BTreeMap::new();
        for (name, text) in definitions {
            let valid = name.chars().next().is_some_and(|c| c.is_ascii_alphabetic())
                && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
            if !valid || RESERVED.contains(&name.as_str()) {
                return Err((
                    name.clone(),
                    format!(
                        "`{name}` cannot name a definition (letters, digits and _, not {})",
                        RESERVED.join(", ")
                    ),
                ));
            }
            let expr =
                exmex::parse::<f64>(text).map_err(|e| (name.clone(), format!("`{text}`: {e}")))?;
            parsed.insert(name.clone(), expr);
        }
        // Depth-first order: a definition after everything it uses.
        let mut out = Self::default();
        let mut visiting = Vec::new();
        fn visit(
            name: &str,
            parsed: &BTreeMap<String, FlatEx<f64>>,
            visiting: &mut Vec<String>,
            out: &mut Definitions,
        ) -> Result<(), (String, String)> {
            if out.names.iter().any(|n| n == name) {
                return Ok(());
            }
            if let Some(start) = visiting.iter().position(|n| n == name) {
                let mut cycle = visiting[start..].to_vec();
                cycle.push(name.to_string());
                return Err((
                    name.to_string(),
                    format!(
                        "definitions use each other in a cycle: {}",
                        cycle.join(" → ")
                    ),
                ));
            }
            visiting.push(name.to_string());
            let expr = &parsed[name];
            for used in expr.var_names() {
                if !VARIABLES.contains(&used.as_str()) {
                    if parsed.contains_key(used) {
                        visit(used, parsed, visiting, out)?;
                    } else {
                        return Err((
                            name.to_string(),
                            format!(
                                "unknown variable `{used}` (allowed: x, y, z, t and the definitions)"
                            ),
                        ));
                    }
                }
            }
            visiting.pop();
            let slots = slots(expr, 4, &out.names)
                .map_err(|unknown| (name.to_string(), format!("unknown variable `{unknown}`")))?;
            out.compiled.push(Compiled {
                expr: Box::new(expr.clone()),
                slots,
            });
            out.names.push(name.to_string());
            Ok(())
        }
        for name in parsed.keys() {
            visit(name, &parsed, &mut visiting, &mut out)?;
        }
        Ok(out)
    }

    /// Fills `values` = [x, y, z, t, definitions…] for a point and time.
    fn fill(&self, values: &mut [f64]) -> Result<(), String> {
        for (i, c) in self.compiled.iter().enumerate() {
            values[4 + i] = c
                .eval(values)
                .map_err(|e| format!("definition `{}`: {e}", self.names[i]))?;
        }
        Ok(())
    }
}

/// One component of a field.
#[derive(Debug, Clone)]
enum Part {
    Constant(f64),
    Expression(Compiled),
}

/// A D-vector field v(x, t).
#[derive(Debug, Clone)]
pub struct VectorField<const D: usize> {
    components: Vec<Part>,
    definitions: Definitions,
    /// Whether any component reads a definition (otherwise they are not evaluated).
    uses_definitions: bool,
}

impl<const D: usize> VectorField<D> {
    /// Compiles `components`; `allow_time` says whether `t` may appear directly. The
    /// error is a message for the key the components came from.
    pub fn compile(
        components: &[Component],
        allow_time: bool,
        definitions: &Definitions,
    ) -> Result<Self, String> {
        if components.len() != D {
            return Err(format!(
                "{} components given, the scene is {D}-dimensional",
                components.len()
            ));
        }
        let allowed = if allow_time { 4 } else { 3 };
        let components = components
            .iter()
            .enumerate()
            .map(|(k, c)| match c {
                Component::Number(v) => Ok(Part::Constant(*v)),
                Component::Expression(text) => {
                    let expr = exmex::parse::<f64>(text)
                        .map_err(|e| format!("component {k}: `{text}`: {e}"))?;
                    let slots = slots(&expr, allowed, &definitions.names).map_err(|name| {
                        format!(
                            "component {k}: `{text}`: unknown variable `{name}` (allowed: {}{})",
                            VARIABLES[..allowed].join(", "),
                            if definitions.names.is_empty() {
                                ""
                            } else {
                                " and the definitions"
                            }
                        )
                    })?;
                    Ok(Part::Expression(Compiled {
                        expr: Box::new(expr),
                        slots,
                    }))
                }
            })
            .collect::<Result<Vec<_>, String>>()?;
        let uses_definitions = components.iter().any(|c| match c {
            Part::Expression(e) => e.slots.iter().any(|&s| s >= 4),
            Part::Constant(_) => false,
        });
        Ok(Self {
            components,
            definitions: definitions.clone(),
            uses_definitions,
        })
    }

    /// The field at position `x` and time `t`.
    pub fn eval(&self, x: &SVector<f64, D>, t: f64) -> Result<SVector<f64, D>, String> {
        let mut values = [0.0; 4 + MAX_DEFINITIONS];
        values[..D].copy_from_slice(x.as_slice());
        values[3] = t;
        if self.uses_definitions {
            self.definitions.fill(&mut values)?;
        }
        let mut out = SVector::<f64, D>::zeros();
        for (k, c) in self.components.iter().enumerate() {
            out[k] = match c {
                Part::Constant(v) => *v,
                Part::Expression(e) => {
                    e.eval(&values).map_err(|e| format!("component {k}: {e}"))?
                }
            };
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn defs(pairs: &[(&str, &str)]) -> Result<Definitions, (String, String)> {
        Definitions::compile(
            &pairs
                .iter()
                .map(|(a, b)| (a.to_string(), b.to_string()))
                .collect(),
        )
    }

    #[test]
    fn definitions_chain_in_any_order() {
        // `h` uses `r`, which sorts after it.
        let d = defs(&[("r", "sqrt(x^2 + y^2)"), ("h", "2 * r + t")]).unwrap();
        let f = VectorField::<2>::compile(
            &[
                Component::Expression("h * x".into()),
                Component::Expression("r".into()),
            ],
            true,
            &d,
        )
        .unwrap();
        let v = f.eval(&SVector::<f64, 2>::new(3.0, 4.0), 0.5).unwrap();
        assert_eq!(v, SVector::<f64, 2>::new((2.0 * 5.0 + 0.5) * 3.0, 5.0));
    }

    #[test]
    fn cycles_unknown_names_and_reserved_names_are_errors() {
        let (name, m) = defs(&[("a", "b + 1"), ("b", "2 * a")]).unwrap_err();
        assert!(
            m.contains("cycle") && m.contains("a → b → a"),
            "{name}: {m}"
        );
        let (name, m) = defs(&[("a", "q + 1")]).unwrap_err();
        assert_eq!(name, "a");
        assert!(m.contains("`q`"), "{m}");
        assert!(defs(&[("t", "1")]).unwrap_err().1.contains("cannot name"));
        assert!(defs(&[("2a", "1")]).is_err());
        // A field may not use an undefined name, and a velocity may not use t directly.
        let d = defs(&[("r", "x")]).unwrap();
        let e =
            VectorField::<1>::compile(&[Component::Expression("s".into())], true, &d).unwrap_err();
        assert!(
            e.contains("unknown variable `s`") && e.contains("definitions"),
            "{e}"
        );
        assert!(
            VectorField::<1>::compile(&[Component::Expression("t".into())], false, &d).is_err()
        );
    }
}
