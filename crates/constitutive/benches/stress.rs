//! Stress evaluation per particle for every model in 2D and 3D (plastic models include
//! their return-mapping step).

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::SMatrix;
use umls_constitutive::{
    ConeFit, Constitutive, DruckerPrager, ElasticParameters, ElastoPlastic, FixedCorotated,
    LinearElastic, NeoHookean, StVenantKirchhoff, VonMises, WeaklyCompressibleFluid,
};

const PARTICLES: usize = 10_000;

/// Deterministic deformation gradients near the identity.
fn deformations<const D: usize>() -> Vec<SMatrix<f64, D, D>> {
    let mut state = 7u64;
    let mut next = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.1
    };
    (0..PARTICLES)
        .map(|_| SMatrix::<f64, D, D>::identity() + SMatrix::<f64, D, D>::from_fn(|_, _| next()))
        .collect()
}

fn bench_model<const D: usize, M: Constitutive<D>>(c: &mut Criterion, group: &str, model: &M) {
    let fs = deformations::<D>();
    let mut states: Vec<M::State> = vec![model.initial_state(); PARTICLES];
    let mut g = c.benchmark_group(group);
    g.throughput(Throughput::Elements(PARTICLES as u64));
    g.sample_size(20);
    g.bench_function(BenchmarkId::from_parameter(model.name()), |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for (f, state) in fs.iter().zip(states.iter_mut()) {
                model.return_map(f, state).expect("det F > 0");
                acc += model.kirchhoff_stress(f, state).expect("det F > 0")[(0, 0)];
            }
            acc
        })
    });
    g.finish();
}

fn all_models<const D: usize>(c: &mut Criterion, group: &str) {
    let p = ElasticParameters::from_young_poisson(1e6, 0.3).expect("valid");
    bench_model::<D, _>(c, group, &LinearElastic { parameters: p });
    bench_model::<D, _>(c, group, &NeoHookean { parameters: p });
    bench_model::<D, _>(c, group, &StVenantKirchhoff { parameters: p });
    bench_model::<D, _>(c, group, &FixedCorotated { parameters: p });
    bench_model::<D, _>(
        c,
        group,
        &WeaklyCompressibleFluid::new(1e6, 7.0).expect("valid"),
    );
}

fn plastic<const D: usize>(c: &mut Criterion, group: &str) {
    let p = ElasticParameters::from_young_poisson(1e6, 0.3).expect("valid");
    let dp = DruckerPrager::from_mohr_coulomb(1e3, 0.5, 0.0, ConeFit::PlaneStrain).expect("valid");
    bench_model::<D, _>(c, group, &ElastoPlastic::new(p, dp));
    bench_model::<D, _>(
        c,
        group,
        &ElastoPlastic::new(p, VonMises::new(1e4, 1e4).expect("valid")),
    );
}

fn stress(c: &mut Criterion) {
    all_models::<2>(c, "stress_2d");
    plastic::<2>(c, "stress_2d");
    all_models::<3>(c, "stress_3d");
    plastic::<3>(c, "stress_3d");
}

criterion_group!(benches, stress);
criterion_main!(benches);
