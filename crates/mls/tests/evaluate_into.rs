//! `UmlsKernel::evaluate_into` (the engine's path: the fit written straight into the
//! caller's arrays) gives the bits of `evaluate` for every gradient and basis, rejects
//! slices of the wrong length by name, and has no stencil cap with the reconstructed
//! gradient.

mod common;

use nalgebra::Vector2;
use proptest::prelude::*;
use umls_mesh::{Located, Orientation, SimplexMesh};
use umls_mls::{
    GradientKind, Linear, MAX_STENCIL, MlsError, PolynomialBasis, Quadratic, Stencil, UmlsKernel,
};

/// `evaluate_into` against `evaluate` at one point, bit for bit, or the same error.
fn same_as_evaluate<const D: usize, const N: usize, B: PolynomialBasis<D, N>>(
    mesh: &SimplexMesh<D>,
    s: usize,
    raw: &[f64],
) -> Result<(), TestCaseError> {
    let kernel = UmlsKernel::new(mesh);
    let x = common::point_in(mesh, s, raw);
    for gradient in [
        GradientKind::Reconstructed,
        GradientKind::Full,
        GradientKind::FrozenEta,
    ] {
        let mut stencil = Stencil::new();
        let expected = kernel.evaluate::<N, B>(mesh, s as u32, &x, gradient, &mut stencil);
        let got = common::evaluate_into_vecs::<D, N, B>(&kernel, mesh, s, &x, gradient);
        match (expected, got) {
            (Ok(()), Ok(((nodes, values, gradients), condition))) => {
                prop_assert_eq!(condition.to_bits(), stencil.condition_number().to_bits());
                common::same_entries(
                    (&nodes, &values, &gradients),
                    (stencil.nodes(), stencil.values(), stencil.gradients()),
                )?;
            }
            (Err(a), Err(b)) => prop_assert_eq!(a.to_string(), b.to_string()),
            (a, b) => prop_assert!(false, "evaluate {:?}, evaluate_into {:?}", a, b),
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn writes_the_bits_of_evaluate_in_2d(
        mesh in common::rectangle(), pick in any::<prop::sample::Index>(),
        raw in prop::array::uniform3(0.0f64..1.0),
    ) {
        let s = pick.index(mesh.simplex_count());
        same_as_evaluate::<2, 3, Linear>(&mesh, s, &raw)?;
        same_as_evaluate::<2, 6, Quadratic>(&mesh, s, &raw)?;
    }

    #[test]
    fn writes_the_bits_of_evaluate_in_3d(
        mesh in common::cuboid(), pick in any::<prop::sample::Index>(),
        raw in prop::array::uniform4(0.0f64..1.0),
    ) {
        let s = pick.index(mesh.simplex_count());
        same_as_evaluate::<3, 4, Linear>(&mesh, s, &raw)?;
        same_as_evaluate::<3, 10, Quadratic>(&mesh, s, &raw)?;
    }
}

/// A fan of `n` triangles around the origin: every triangle's 1-ring holds the centre
/// and all `n` rim vertices.
fn fan(n: usize) -> SimplexMesh<2> {
    let mut vertices = vec![Vector2::zeros()];
    for k in 0..n {
        let angle = std::f64::consts::TAU * k as f64 / n as f64;
        vertices.push(Vector2::new(angle.cos(), angle.sin()));
    }
    let simplices = (0..n as u32)
        .flat_map(|k| [0, 1 + k, 1 + (k + 1) % n as u32])
        .collect();
    SimplexMesh::new(vertices, simplices, Orientation::Reject).expect("a valid fan")
}

#[test]
fn a_ring_beyond_the_fixed_stencil_is_evaluated_in_place_and_reproduces_linear_fields() {
    let mesh = fan(80);
    let ring = mesh.topology().one_ring(0).len();
    assert!(ring > MAX_STENCIL, "ring of {ring}");
    let kernel = UmlsKernel::new(&mesh);
    let x = mesh.point_at(
        0,
        &umls_mesh::Barycentric::from_slice(&[0.5, 0.3, 0.2]).unwrap(),
    );
    // The fixed-capacity stencil cannot hold it, and says so.
    let mut stencil = Stencil::new();
    let err = kernel
        .evaluate::<3, Linear>(&mesh, 0, &x, GradientKind::Reconstructed, &mut stencil)
        .unwrap_err();
    assert!(matches!(
        err,
        MlsError::StencilOverflow {
            simplex: Some(0),
            ..
        }
    ));
    // The caller's slices can.
    let mut nodes = vec![0u32; ring];
    let mut values = vec![0.0; ring];
    let mut gradients = vec![Vector2::zeros(); ring];
    kernel
        .evaluate_into::<3, Linear>(
            &mesh,
            &Located {
                simplex: 0,
                barycentric: mesh.barycentric(0, &x),
            },
            &x,
            GradientKind::Reconstructed,
            &mut nodes,
            &mut values,
            &mut gradients,
        )
        .unwrap();
    let field = |p: &Vector2<f64>| 0.7 - 1.3 * p.x + 2.1 * p.y;
    let mut value = 0.0;
    let mut gradient = Vector2::zeros();
    for ((&v, n), g) in nodes.iter().zip(&values).zip(&gradients) {
        let u = field(mesh.vertex(v as usize));
        value += n * u;
        gradient += g * u;
    }
    assert!(
        (value - field(&x)).abs() < 1e-12,
        "{value} against {}",
        field(&x)
    );
    assert!(
        (gradient - Vector2::new(-1.3, 2.1)).norm() < 1e-11,
        "{gradient}"
    );
}

#[test]
fn slices_of_the_wrong_length_are_named_with_the_host() {
    let mesh = fan(6);
    let kernel = UmlsKernel::new(&mesh);
    let x = mesh.point_at(
        2,
        &umls_mesh::Barycentric::from_slice(&[0.4, 0.3, 0.3]).unwrap(),
    );
    let ring = mesh.topology().one_ring(2).len();
    let mut nodes = vec![0u32; ring];
    let mut values = vec![0.0; ring - 1];
    let mut gradients = vec![Vector2::zeros(); ring];
    let err = kernel
        .evaluate_into::<3, Linear>(
            &mesh,
            &Located {
                simplex: 2,
                barycentric: mesh.barycentric(2, &x),
            },
            &x,
            GradientKind::Reconstructed,
            &mut nodes,
            &mut values,
            &mut gradients,
        )
        .unwrap_err();
    assert!(matches!(
        err,
        MlsError::OutputLength { simplex: 2, ring: r, values: v, .. } if r == ring && v == ring - 1
    ));
    assert!(err.to_string().contains("simplex 2"), "{err}");
}
