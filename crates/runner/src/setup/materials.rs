//! `[[materials]]`: each entry checked and turned into its constitutive model, with
//! errors naming the key of the parameter the model rejects.

use umls_constitutive::table::{ElasticModel, Model, PlasticModel};
use umls_constitutive::{
    ConeFit, DruckerPrager, ElasticParameters, ElastoPlastic, FixedCorotated, LinearElastic,
    NeoHookean, StVenantKirchhoff, VonMises, WeaklyCompressibleFluid,
};

use crate::error::Result;
use crate::scene::Scene;
use crate::schema::{MaterialSpec, SolidSpec};

/// The scene's material models and names, by index.
pub(super) fn materials(scene: &Scene) -> Result<(Vec<Model<PlasticModel>>, Vec<String>)> {
    let spec = &scene.spec;
    if spec.materials.is_empty() {
        return Err(scene.value_error("materials", "at least one material is needed"));
    }
    if spec.materials.len() > usize::from(u16::MAX) {
        return Err(scene.value_error("materials", "too many materials"));
    }
    let models = (0..spec.materials.len())
        .map(|i| material(scene, i))
        .collect::<Result<Vec<_>>>()?;
    let names = spec
        .materials
        .iter()
        .map(|m| m.name().to_string())
        .collect();
    Ok((models, names))
}

fn material(scene: &Scene, index: usize) -> Result<Model<PlasticModel>> {
    let spec = &scene.spec.materials[index];
    let key = |field: &str| format!("materials[{index}].{field}");
    // The key of the parameter the model rejected, with angles shown in the degrees the
    // file gives them in.
    let bad = |e: umls_constitutive::ConstitutiveError| match e {
        umls_constitutive::ConstitutiveError::InvalidParameter {
            parameter,
            value,
            reason,
        } => {
            let (field, value) = match parameter {
                "E (Young's modulus)" => ("young", value),
                "ν (Poisson's ratio)" => ("poisson", value),
                "cohesion" => ("cohesion", value),
                "friction angle (rad)" => ("friction_angle", value.to_degrees()),
                "dilatancy angle (rad)" => ("dilatancy_angle", value.to_degrees()),
                "yield stress" => ("yield_stress", value),
                "hardening modulus" => ("hardening", value),
                "K (bulk modulus)" => ("bulk", value),
                "γ (exponent)" => ("gamma", value),
                other => (other, value),
            };
            let reason = reason
                .replace("[0, π/2)", "[0°, 90°)")
                .replace("[0, friction angle]", "[0°, friction_angle]");
            scene.value_error(key(field), format!("{value}: {reason}"))
        }
        other => scene.value_error(key("model"), other.to_string()),
    };
    let density = spec.density();
    if !(density.is_finite() && density > 0.0) {
        return Err(scene.value_error(key("density"), "must be finite and positive"));
    }
    let elastic = |young: f64, poisson: f64| {
        ElasticParameters::from_young_poisson(young, poisson).map_err(bad)
    };
    let solid = |m: &SolidSpec| elastic(m.young, m.poisson);
    Ok(match spec {
        MaterialSpec::LinearElastic(m) => Model::Elastic(ElasticModel::Linear(LinearElastic {
            parameters: solid(m)?,
        })),
        MaterialSpec::NeoHookean(m) => Model::Elastic(ElasticModel::NeoHookean(NeoHookean {
            parameters: solid(m)?,
        })),
        MaterialSpec::StVenantKirchhoff(m) => {
            Model::Elastic(ElasticModel::StVenantKirchhoff(StVenantKirchhoff {
                parameters: solid(m)?,
            }))
        }
        MaterialSpec::FixedCorotated(m) => {
            Model::Elastic(ElasticModel::Corotated(FixedCorotated {
                parameters: solid(m)?,
            }))
        }
        MaterialSpec::Fluid(m) => Model::Elastic(ElasticModel::Fluid(
            WeaklyCompressibleFluid::new(m.bulk, m.gamma.unwrap_or(7.0)).map_err(bad)?,
        )),
        MaterialSpec::DruckerPrager(m) => {
            let criterion = DruckerPrager::from_mohr_coulomb(
                m.cohesion,
                m.friction_angle.to_radians(),
                m.dilatancy_angle.unwrap_or(0.0).to_radians(),
                ConeFit::PlaneStrain,
            )
            .map_err(bad)?;
            Model::Plastic(PlasticModel::DruckerPrager(ElastoPlastic::new(
                elastic(m.young, m.poisson)?,
                criterion,
            )))
        }
        MaterialSpec::VonMises(m) => {
            let criterion =
                VonMises::new(m.yield_stress, m.hardening.unwrap_or(0.0)).map_err(bad)?;
            Model::Plastic(PlasticModel::VonMises(ElastoPlastic::new(
                elastic(m.young, m.poisson)?,
                criterion,
            )))
        }
    })
}
