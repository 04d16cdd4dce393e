//! A material table: several materials in one simulation, chosen per particle by an id in
//! the particle state.
//!
//! The engine is generic over one material type; a scene picks models at run time, so
//! this adapter dispatches with a `match`. Plasticity is a type parameter: a scene
//! without plastic materials runs `MaterialTable<NoPlasticity>`, whose state is only the
//! id and whose plastic branch does not exist, so elastic scenes never pay for it.

use nalgebra::SMatrix;

use crate::{
    Constitutive, ConstitutiveError, DruckerPrager, ElastoPlastic, FixedCorotated, LinearElastic,
    NeoHookean, PlasticState, StVenantKirchhoff, VonMises, WeaklyCompressibleFluid,
};

/// The elastic (and fluid) models, available in every dimension.
#[derive(Debug, Clone)]
pub enum ElasticModel {
    /// Small-strain linear elasticity.
    Linear(LinearElastic),
    /// Compressible neo-Hookean.
    NeoHookean(NeoHookean),
    /// St. Venant–Kirchhoff.
    StVenantKirchhoff(StVenantKirchhoff),
    /// Fixed corotated.
    Corotated(FixedCorotated),
    /// Weakly compressible fluid.
    Fluid(WeaklyCompressibleFluid),
}

macro_rules! elastic_dispatch {
    ($self:expr, $m:ident => $body:expr) => {
        match $self {
            ElasticModel::Linear($m) => $body,
            ElasticModel::NeoHookean($m) => $body,
            ElasticModel::StVenantKirchhoff($m) => $body,
            ElasticModel::Corotated($m) => $body,
            ElasticModel::Fluid($m) => $body,
        }
    };
}

/// Calls `$method(f, state)` on the model of a particle's material: elastic models with
/// the unit state, plastic ones with the particle's plastic state.
macro_rules! per_material {
    ($table:expr, $method:ident, $f:expr, $state:expr) => {
        match $table.get($state.material)? {
            Model::Elastic(m) => {
                elastic_dispatch!(m, m => Constitutive::<D>::$method(m, $f, &()))
            }
            Model::Plastic(p) => p.model().$method($f, &$state.plastic),
        }
    };
}

/// Plastic models (D = 2 plane strain, D = 3).
#[derive(Debug, Clone)]
pub enum PlasticModel {
    /// Drucker–Prager.
    DruckerPrager(ElastoPlastic<DruckerPrager>),
    /// von Mises (J2).
    VonMises(ElastoPlastic<VonMises>),
}

/// The plastic part of a table without plastic models (it has no values).
#[derive(Debug, Clone)]
pub enum NoPlasticity {}

/// What a table needs of its plastic part.
pub trait PlasticPart<const D: usize>: Send + Sync + std::fmt::Debug {
    /// Per-particle plastic state (`()` when there is none).
    type State: Clone + std::fmt::Debug + PartialEq + Send + Sync + Default;
    /// The model as a constitutive law.
    fn model(&self) -> &dyn Constitutive<D, State = Self::State>;
    /// Names of the state scalars written to output.
    fn scalar_names() -> &'static [&'static str];
    /// The state scalars of an elastic particle in a table with plastic materials.
    fn elastic_scalars(out: &mut Vec<f64>);
}

impl<const D: usize> PlasticPart<D> for NoPlasticity {
    type State = ();
    fn model(&self) -> &dyn Constitutive<D, State = ()> {
        match *self {}
    }
    fn scalar_names() -> &'static [&'static str] {
        &[]
    }
    fn elastic_scalars(_: &mut Vec<f64>) {}
}

impl<const D: usize> PlasticPart<D> for PlasticModel
where
    ElastoPlastic<DruckerPrager>: Constitutive<D, State = PlasticState<D>>,
    ElastoPlastic<VonMises>: Constitutive<D, State = PlasticState<D>>,
{
    type State = PlasticState<D>;
    fn model(&self) -> &dyn Constitutive<D, State = PlasticState<D>> {
        match self {
            PlasticModel::DruckerPrager(m) => m,
            PlasticModel::VonMises(m) => m,
        }
    }
    fn scalar_names() -> &'static [&'static str] {
        &["plastic_strain", "plastic_jacobian"]
    }
    fn elastic_scalars(out: &mut Vec<f64>) {
        out.extend([0.0, 1.0]);
    }
}

/// One material of the table.
#[derive(Debug, Clone)]
pub enum Model<P> {
    /// An elastic or fluid model.
    Elastic(ElasticModel),
    /// A plastic model.
    Plastic(P),
}

/// Particle state: the material id and the plastic state.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TableState<S> {
    /// Index into the table.
    pub material: u16,
    /// Plastic state (unused by elastic materials).
    pub plastic: S,
}

/// Several materials in one simulation.
#[derive(Debug, Clone)]
pub struct MaterialTable<P> {
    /// The models, indexed by [`TableState::material`].
    pub models: Vec<Model<P>>,
}

impl<P> MaterialTable<P> {
    fn get(&self, state_material: u16) -> Result<&Model<P>, ConstitutiveError> {
        self.models
            .get(state_material as usize)
            .ok_or(ConstitutiveError::InvalidParameter {
                parameter: "material id",
                value: f64::from(state_material),
                reason: "no such material in the scene's table",
            })
    }
}

impl<const D: usize, P: PlasticPart<D>> Constitutive<D> for MaterialTable<P> {
    type State = TableState<P::State>;

    fn name(&self) -> &'static str {
        "material table"
    }

    fn initial_state(&self) -> Self::State {
        TableState::default()
    }

    fn return_map(
        &self,
        f: &SMatrix<f64, D, D>,
        state: &mut Self::State,
    ) -> Result<(), ConstitutiveError> {
        match self.get(state.material)? {
            Model::Elastic(_) => Ok(()),
            Model::Plastic(p) => p.model().return_map(f, &mut state.plastic),
        }
    }

    fn kirchhoff_stress(
        &self,
        f: &SMatrix<f64, D, D>,
        state: &Self::State,
    ) -> Result<SMatrix<f64, D, D>, ConstitutiveError> {
        per_material!(self, kirchhoff_stress, f, state)
    }

    fn return_map_and_stress(
        &self,
        f: &SMatrix<f64, D, D>,
        state: &mut Self::State,
    ) -> Result<SMatrix<f64, D, D>, ConstitutiveError> {
        match self.get(state.material)? {
            Model::Elastic(m) => {
                elastic_dispatch!(m, m => Constitutive::<D>::kirchhoff_stress(m, f, &()))
            }
            Model::Plastic(p) => p.model().return_map_and_stress(f, &mut state.plastic),
        }
    }

    fn out_of_plane_stress(
        &self,
        f: &SMatrix<f64, D, D>,
        state: &Self::State,
    ) -> Result<f64, ConstitutiveError> {
        per_material!(self, out_of_plane_stress, f, state)
    }

    fn energy_density(
        &self,
        f: &SMatrix<f64, D, D>,
        state: &Self::State,
    ) -> Result<f64, ConstitutiveError> {
        per_material!(self, energy_density, f, state)
    }

    /// The stiffest material's modulus (the CFL bound must hold for all of them).
    fn p_wave_modulus(&self) -> f64 {
        self.models
            .iter()
            .map(|m| match m {
                Model::Elastic(m) => {
                    elastic_dispatch!(m, m => Constitutive::<D>::p_wave_modulus(m))
                }
                Model::Plastic(p) => p.model().p_wave_modulus(),
            })
            .fold(0.0, f64::max)
    }

    fn state_scalar_names(&self) -> &'static [&'static str] {
        P::scalar_names()
    }

    fn state_scalars(&self, state: &Self::State, out: &mut Vec<f64>) {
        match self.get(state.material) {
            Ok(Model::Plastic(p)) => p.model().state_scalars(&state.plastic, out),
            _ => P::elastic_scalars(out),
        }
    }
}
