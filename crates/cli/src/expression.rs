//! Vector fields given in a scene file: each component a number or an expression in
//! x, y, z and t, parsed once with `exmex` (a maintained, fast expression evaluator) and
//! evaluated per particle.

use exmex::prelude::*;
use nalgebra::SVector;

use crate::schema::Component;

/// The variables an expression may use, in slot order.
const VARIABLES: [&str; 4] = ["x", "y", "z", "t"];

/// One component.
#[derive(Debug, Clone)]
enum Compiled {
    Constant(f64),
    Expression {
        /// Boxed: a flattened expression is large, constants are common.
        expr: Box<FlatEx<f64>>,
        /// For each of the expression's variables (exmex orders them alphabetically),
        /// its slot in [x, y, z, t].
        slots: Vec<usize>,
    },
}

/// A D-vector field v(x, t).
#[derive(Debug, Clone)]
pub struct VectorField<const D: usize> {
    components: Vec<Compiled>,
}

impl<const D: usize> VectorField<D> {
    /// Compiles `components`; `allow_time` says whether `t` may appear. The error is a
    /// message for the key the components came from.
    pub fn compile(components: &[Component], allow_time: bool) -> Result<Self, String> {
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
                Component::Number(v) => Ok(Compiled::Constant(*v)),
                Component::Expression(text) => {
                    let expr = exmex::parse::<f64>(text)
                        .map_err(|e| format!("component {k}: `{text}`: {e}"))?;
                    let slots = expr
                        .var_names()
                        .iter()
                        .map(|name| {
                            VARIABLES[..allowed]
                                .iter()
                                .position(|v| v == name)
                                .ok_or_else(|| {
                                    format!(
                                        "component {k}: `{text}`: unknown variable `{name}` (allowed: {})",
                                        VARIABLES[..allowed].join(", ")
                                    )
                                })
                        })
                        .collect::<Result<Vec<_>, String>>()?;
                    Ok(Compiled::Expression {
                        expr: Box::new(expr),
                        slots,
                    })
                }
            })
            .collect::<Result<Vec<_>, String>>()?;
        Ok(Self { components })
    }

    /// The field at position `x` and time `t`.
    pub fn eval(&self, x: &SVector<f64, D>, t: f64) -> Result<SVector<f64, D>, String> {
        let mut values = [0.0, 0.0, 0.0, t];
        for k in 0..D {
            values[k] = x[k];
        }
        let mut out = SVector::<f64, D>::zeros();
        let mut arguments = Vec::with_capacity(4);
        for (k, c) in self.components.iter().enumerate() {
            out[k] = match c {
                Compiled::Constant(v) => *v,
                Compiled::Expression { expr, slots } => {
                    arguments.clear();
                    arguments.extend(slots.iter().map(|&s| values[s]));
                    expr.eval(&arguments)
                        .map_err(|e| format!("component {k}: {e}"))?
                }
            };
        }
        Ok(out)
    }
}
