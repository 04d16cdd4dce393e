//! C¹ continuity across facets. For random interior facets of every kind (1D points, 2D
//! edges, 3D triangles), evaluate on both sides at distance ε and 2ε from a random facet
//! point. A function continuous across the facet jumps by ≈ 2ε·|∂_n N|, so the jump
//! halves when ε halves (ratio jump(2ε)/jump(ε) ≈ 2); a discontinuous one keeps an O(1)
//! jump (ratio ≈ 1). The UMLS values and reconstructed gradients must be continuous;
//! linear FE gradients must not be (the cell-crossing baseline); the full UMLS gradient
//! inherits the jump of ∇η and is reported; the derivative at frozen η drops that jump
//! and must be continuous.

mod common;

use std::collections::BTreeMap;

use nalgebra::SVector;
use umls_mesh::SimplexMesh;
use umls_mesh::generate::{Diagonal, Lattice};
use umls_mls::{
    CubicBSpline, DEFAULT_SHARPENING, GradientKind, Linear, PolynomialBasis, Profile, Quadratic,
    SharpenedBSpline, Stencil, SupportRadius, UmlsKernel, WeightFunction,
};

const EPS: f64 = 1e-4;

/// Largest differences of values and of gradients (× h) between the two sides.
#[derive(Debug, Clone, Copy, Default)]
struct Jump {
    value: f64,
    gradient: f64,
}

fn difference<const D: usize>(
    a: &[(u32, f64, SVector<f64, D>)],
    b: &[(u32, f64, SVector<f64, D>)],
    h: f64,
) -> Jump {
    let mut merged: BTreeMap<u32, (f64, SVector<f64, D>)> = BTreeMap::new();
    for &(v, n, g) in a {
        merged.insert(v, (n, g));
    }
    for &(v, n, g) in b {
        let e = merged.entry(v).or_insert((0.0, SVector::zeros()));
        e.0 -= n;
        e.1 -= g;
    }
    merged.values().fold(Jump::default(), |j, (n, g)| Jump {
        value: j.value.max(n.abs()),
        gradient: j.gradient.max(g.norm() * h),
    })
}

type Evaluator<'a, const D: usize> =
    dyn Fn(usize, &SVector<f64, D>) -> Vec<(u32, f64, SVector<f64, D>)> + 'a;

/// Jumps at ε and 2ε (relative to h) across facet `local` of simplex `s`.
fn facet_jumps<const D: usize>(
    mesh: &SimplexMesh<D>,
    s: usize,
    local: usize,
    t: usize,
    facet_weights: &[f64],
    eval: &Evaluator<'_, D>,
) -> (Jump, Jump) {
    let verts = mesh.simplex(s);
    let total: f64 = facet_weights.iter().sum();
    let mut y = SVector::<f64, D>::zeros();
    let mut k = 0;
    for (i, &v) in verts.iter().enumerate() {
        if i != local {
            y += mesh.vertex(v as usize) * (facet_weights[k] / total);
            k += 1;
        }
    }
    let inward = mesh.barycentric_gradients(s).as_slice()[local].normalize();
    let h = mesh.max_edge_length();
    let at = |eps: f64| {
        difference(
            &eval(s, &(y + inward * eps * h)),
            &eval(t, &(y - inward * eps * h)),
            h,
        )
    };
    (at(EPS), at(2.0 * EPS))
}

fn umls_evaluator<'a, const D: usize, const N: usize, B: PolynomialBasis<D, N>, W>(
    mesh: &'a SimplexMesh<D>,
    kernel: &'a UmlsKernel<D, W>,
    gradient: GradientKind,
) -> Box<Evaluator<'a, D>>
where
    W: WeightFunction,
{
    Box::new(move |s, x| {
        let mut st = Stencil::new();
        kernel
            .evaluate::<N, B>(mesh, s as u32, x, gradient, &mut st)
            .unwrap();
        st.iter().map(|(v, n, g)| (v, n, *g)).collect()
    })
}

fn linear_fe_evaluator<const D: usize>(mesh: &SimplexMesh<D>) -> Box<Evaluator<'_, D>> {
    Box::new(move |s, x| {
        let lambda = mesh.barycentric(s, x);
        let grads = mesh.barycentric_gradients(s);
        mesh.simplex(s)
            .iter()
            .zip(lambda.as_slice())
            .zip(grads.as_slice())
            .map(|((&v, &l), g)| (v, l, *g))
            .collect()
    })
}

/// Worst-case jump over all interior facets at ε, and the smallest ratio jump(2ε)/jump(ε)
/// over facets where the jump is above round-off.
#[derive(Debug)]
struct Summary {
    value_jump: f64,
    gradient_jump: f64,
    min_value_ratio: f64,
    min_gradient_ratio: f64,
    max_gradient_ratio: f64,
    min_gradient_jump: f64,
    facets: usize,
}

fn survey<const D: usize>(mesh: &SimplexMesh<D>, eval: &Evaluator<'_, D>) -> Summary {
    let mut summary = Summary {
        value_jump: 0.0,
        gradient_jump: 0.0,
        min_value_ratio: f64::INFINITY,
        min_gradient_ratio: f64::INFINITY,
        max_gradient_ratio: 0.0,
        min_gradient_jump: f64::INFINITY,
        facets: 0,
    };
    let mut seed = 12345u64;
    for s in 0..mesh.simplex_count() {
        for local in 0..=D {
            let Some(t) = mesh.topology().neighbor(s, local) else {
                continue;
            };
            if (t as usize) < s {
                continue; // each facet once
            }
            let weights: Vec<f64> = (0..D)
                .map(|_| {
                    seed = seed
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    0.05 + (seed >> 11) as f64 / (1u64 << 53) as f64
                })
                .collect();
            let (j1, j2) = facet_jumps(mesh, s, local, t as usize, &weights, eval);
            summary.facets += 1;
            summary.value_jump = summary.value_jump.max(j1.value);
            summary.gradient_jump = summary.gradient_jump.max(j1.gradient);
            summary.min_gradient_jump = summary.min_gradient_jump.min(j1.gradient);
            // Ratios only where the jump is well above round-off.
            if j1.value > 1e-9 {
                summary.min_value_ratio = summary.min_value_ratio.min(j2.value / j1.value);
            }
            if j1.gradient > 1e-9 {
                summary.min_gradient_ratio =
                    summary.min_gradient_ratio.min(j2.gradient / j1.gradient);
                summary.max_gradient_ratio =
                    summary.max_gradient_ratio.max(j2.gradient / j1.gradient);
            }
        }
    }
    summary
}

fn meshes_2d() -> Vec<SimplexMesh<2>> {
    [
        (Diagonal::Right, 0.2, 0.0),
        (Diagonal::Alternating, 0.2, 0.6),
        (Diagonal::Crossed, 0.15, 1.1),
    ]
    .into_iter()
    .enumerate()
    .map(|(i, (d, j, a))| {
        Lattice::new([0.0, 0.0], [1.0, 1.0], [6, 5])
            .jitter(j, i as u64 + 3)
            .rotate_by(a)
            .triangles(d)
            .unwrap()
    })
    .collect()
}

fn assert_continuous(label: &str, s: &Summary) {
    eprintln!("{label}: {s:?}");
    assert!(s.facets > 0);
    // Continuous: the jump is O(ε) (|∂_n N| h ≲ 10) and doubles with ε.
    assert!(
        s.value_jump < 20.0 * EPS,
        "{label}: value jump {} not O(ε)",
        s.value_jump
    );
    assert!(
        s.gradient_jump < 200.0 * EPS,
        "{label}: gradient jump {} not O(ε)",
        s.gradient_jump
    );
    assert!(
        s.min_value_ratio > 1.9,
        "{label}: value jump ratio {}",
        s.min_value_ratio
    );
    assert!(
        s.min_gradient_ratio > 1.9,
        "{label}: gradient jump ratio {}",
        s.min_gradient_ratio
    );
}

#[test]
fn umls_values_and_reconstructed_gradients_are_continuous() {
    let line = Lattice::new([0.0], [1.0], [12])
        .jitter(0.2, 5)
        .segments()
        .unwrap();
    let k1 = UmlsKernel::new(&line);
    assert_continuous(
        "1D linear",
        &survey(
            &line,
            &*umls_evaluator::<1, 2, Linear, _>(&line, &k1, GradientKind::Reconstructed),
        ),
    );
    assert_continuous(
        "1D quadratic",
        &survey(
            &line,
            &*umls_evaluator::<1, 3, Quadratic, _>(&line, &k1, GradientKind::Reconstructed),
        ),
    );
    for mesh in meshes_2d() {
        let k2 = UmlsKernel::new(&mesh);
        assert_continuous(
            "2D linear",
            &survey(
                &mesh,
                &*umls_evaluator::<2, 3, Linear, _>(&mesh, &k2, GradientKind::Reconstructed),
            ),
        );
    }
    let tets = Lattice::new([0.0; 3], [1.0; 3], [3, 3, 3])
        .jitter(0.2, 9)
        .rotate_about([1.0, 1.0, 0.0], 0.4)
        .tetrahedra()
        .unwrap();
    let k3 = UmlsKernel::new(&tets);
    assert_continuous(
        "3D linear",
        &survey(
            &tets,
            &*umls_evaluator::<3, 4, Linear, _>(&tets, &k3, GradientKind::Reconstructed),
        ),
    );
}

/// Every UMLS variant the CLI names (docs/umls-kernel.md): the wide per-vertex reach,
/// the paper's global radius, the element-size radius, Wendland and sharpened weights,
/// and the quadratic basis with its ridge,
/// in 2D and 3D. Narrow supports make vertices enter and leave by their distance weight
/// too; that weight is C² in x, so continuity holds as for the default.
#[test]
fn every_umls_variant_is_continuous() {
    let variants = [
        (
            "wide",
            Profile::CubicBSpline,
            SupportRadius::PerVertex { factor: 1.0 },
            1,
        ),
        (
            "paper",
            Profile::CubicBSpline,
            SupportRadius::Global { factor: 1.0 },
            1,
        ),
        ("wendland", Profile::WendlandC2, SupportRadius::default(), 1),
        (
            "narrow",
            Profile::CubicBSpline,
            SupportRadius::IncidentEdge { factor: 0.6 },
            1,
        ),
        (
            "sharpened",
            Profile::Sharpened(SharpenedBSpline {
                epsilon: DEFAULT_SHARPENING,
            }),
            SupportRadius::default(),
            1,
        ),
        (
            "eta4",
            Profile::CubicBSpline,
            SupportRadius::IncidentEdge { factor: 1.4 },
            4,
        ),
        (
            "eta8",
            Profile::CubicBSpline,
            SupportRadius::IncidentEdge { factor: 2.8 },
            8,
        ),
        (
            "element-size",
            Profile::CubicBSpline,
            SupportRadius::ElementSize { factor: 1.0 },
            1,
        ),
    ];
    let tets = Lattice::new([0.0; 3], [1.0; 3], [3, 3, 3])
        .jitter(0.2, 9)
        .rotate_about([1.0, 1.0, 0.0], 0.4)
        .tetrahedra()
        .unwrap();
    for (label, profile, support, exponent) in variants {
        for mesh in meshes_2d() {
            let k = UmlsKernel::with_weight(&mesh, profile, support)
                .unwrap()
                .with_diminishing_exponent(exponent)
                .unwrap();
            assert_continuous(
                &format!("2D {label}"),
                &survey(
                    &mesh,
                    &*umls_evaluator::<2, 3, Linear, _>(&mesh, &k, GradientKind::Reconstructed),
                ),
            );
        }
        let k = UmlsKernel::with_weight(&tets, profile, support)
            .unwrap()
            .with_diminishing_exponent(exponent)
            .unwrap();
        assert_continuous(
            &format!("3D {label}"),
            &survey(
                &tets,
                &*umls_evaluator::<3, 4, Linear, _>(&tets, &k, GradientKind::Reconstructed),
            ),
        );
    }
    // The quadratic basis with the ridge the CLI's `umls-quadratic` uses: solvable on
    // wall and corner vertices, and continuous because the ridge is always on.
    for mesh in meshes_2d() {
        let mut k = UmlsKernel::new(&mesh);
        k.conditioning.higher_order_ridge = 1e-3;
        assert_continuous(
            "2D quadratic with ridge",
            &survey(
                &mesh,
                &*umls_evaluator::<2, 6, Quadratic, _>(&mesh, &k, GradientKind::Reconstructed),
            ),
        );
    }
    let mut k = UmlsKernel::<3, CubicBSpline>::new(&tets);
    k.conditioning.higher_order_ridge = 1e-3;
    assert_continuous(
        "3D quadratic with ridge",
        &survey(
            &tets,
            &*umls_evaluator::<3, 10, Quadratic, _>(&tets, &k, GradientKind::Reconstructed),
        ),
    );
}

/// The derivative at frozen η (`GradientKind::FrozenEta`) keeps only η_v ∇d_v of the
/// weights' gradients: η is continuous and vanishes with its vertex's entry, ∇d is C¹, so
/// the gradient is continuous across facets, in 2D and 3D, with the default support and
/// the wide one, where the full gradient (above) jumps by O(1).
#[test]
fn frozen_eta_gradient_is_continuous() {
    let tets = Lattice::new([0.0; 3], [1.0; 3], [3, 3, 3])
        .jitter(0.2, 9)
        .rotate_about([1.0, 1.0, 0.0], 0.4)
        .tetrahedra()
        .unwrap();
    for support in [
        SupportRadius::default(),
        SupportRadius::PerVertex { factor: 1.0 },
    ] {
        for mesh in meshes_2d() {
            let k = UmlsKernel::with_weight(&mesh, CubicBSpline, support).unwrap();
            let s = survey(
                &mesh,
                &*umls_evaluator::<2, 3, Linear, _>(&mesh, &k, GradientKind::FrozenEta),
            );
            assert_continuous(&format!("2D frozen η, {support:?}"), &s);
        }
        let k = UmlsKernel::with_weight(&tets, CubicBSpline, support).unwrap();
        let s = survey(
            &tets,
            &*umls_evaluator::<3, 4, Linear, _>(&tets, &k, GradientKind::FrozenEta),
        );
        assert_continuous(&format!("3D frozen η, {support:?}"), &s);
    }
}

#[test]
fn linear_fe_gradients_jump_by_order_one() {
    for mesh in meshes_2d() {
        let s = survey(&mesh, &*linear_fe_evaluator(&mesh));
        eprintln!("2D linear FE: {s:?}");
        // Values are continuous (C⁰ elements) ...
        assert!(s.value_jump < 20.0 * EPS && s.min_value_ratio > 1.9);
        // ... gradients jump by O(1) on every facet and do not shrink with ε.
        assert!(
            s.min_gradient_jump > 0.05,
            "FE gradient jump {}",
            s.min_gradient_jump
        );
        assert!(s.max_gradient_ratio < 1.01);
    }
    let tets = Lattice::new([0.0; 3], [1.0; 3], [3, 3, 3])
        .jitter(0.2, 9)
        .tetrahedra()
        .unwrap();
    let s = survey(&tets, &*linear_fe_evaluator(&tets));
    eprintln!("3D linear FE: {s:?}");
    assert!(s.gradient_jump > 0.5 && s.max_gradient_ratio < 1.01);
}

/// The full derivative carries ∇w_v = ∇η_v d_v + η_v ∇d_v, and ∇η_v = Σ A_{v,n} ∇λ_n jumps
/// across every facet: the full gradient is discontinuous (ratio ≈ 1, O(1) jump) while the
/// values stay continuous. This is why MPM uses the reconstructed gradient.
#[test]
fn full_umls_gradient_jumps_across_facets() {
    for mesh in meshes_2d() {
        let k = UmlsKernel::new(&mesh);
        let s = survey(
            &mesh,
            &*umls_evaluator::<2, 3, Linear, _>(&mesh, &k, GradientKind::Full),
        );
        eprintln!("2D full gradient: {s:?}");
        assert!(s.value_jump < 20.0 * EPS && s.min_value_ratio > 1.9);
        assert!(
            s.min_gradient_jump > 0.05,
            "full gradient jump {}",
            s.min_gradient_jump
        );
        assert!(
            s.max_gradient_ratio < 1.05,
            "full gradient ratio {}",
            s.max_gradient_ratio
        );
    }
}
