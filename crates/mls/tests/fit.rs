//! `UmlsKernel::fit_into` and `UmlsFit::visit` (the fit kept as weights and M⁻¹, the
//! entries rebuilt later, as an engine storing factored stencils does) give the bits of
//! `evaluate_into` for both bases in 2D and 3D; the fit survives its flat form; wrong
//! lengths are named.

mod common;

use nalgebra::{SVector, Vector2};
use proptest::prelude::*;
use umls_mesh::{Barycentric, Located, SimplexMesh};
use umls_mls::{GradientKind, Linear, MlsError, PolynomialBasis, Quadratic, UmlsFit, UmlsKernel};

/// The host `s` with the barycentric coordinates of `x`.
fn located<const D: usize>(mesh: &SimplexMesh<D>, s: usize, x: &SVector<f64, D>) -> Located<D> {
    Located {
        simplex: s as u32,
        barycentric: mesh.barycentric(s, x),
    }
}

/// Fit, flatten, read back and rebuild at one point: the entries of `evaluate_into`,
/// bit for bit, with the offsets x_v − x; or the same error.
fn rebuilt_as_evaluated<const D: usize, const N: usize, B: PolynomialBasis<D, N>>(
    mesh: &SimplexMesh<D>,
    s: usize,
    raw: &[f64],
) -> Result<(), TestCaseError> {
    let kernel = UmlsKernel::new(mesh);
    let x = common::point_in(mesh, s, raw);
    let ring = mesh.topology().one_ring(s).len();
    let expected =
        common::evaluate_into_vecs::<D, N, B>(&kernel, mesh, s, &x, GradientKind::Reconstructed);
    let mut weights = vec![0.0; ring];
    let mut scratch = vec![SVector::<f64, D>::zeros(); ring];
    let fit = kernel.fit_into::<N, B>(mesh, &located(mesh, s, &x), &x, &mut weights, &mut scratch);
    match (expected, fit) {
        (Ok(((nodes, values, gradients), _)), Ok(fit)) => {
            let mut flat = vec![0.0; UmlsFit::<N>::LEN];
            fit.write(&mut flat).unwrap();
            let fit = UmlsFit::<N>::read(&flat).unwrap();
            let mut rebuilt: common::Entries<D> = (Vec::new(), Vec::new(), Vec::new());
            let mut offsets_right = true;
            let visited = fit.visit::<D, B>(mesh, s as u32, &x, &weights, |v, n, g, offset| {
                offsets_right &= *offset == mesh.vertex(v as usize) - x;
                rebuilt.0.push(v);
                rebuilt.1.push(n);
                rebuilt.2.push(*g);
            });
            prop_assert!(visited.is_ok(), "{:?}", visited);
            prop_assert!(offsets_right);
            common::same_entries(
                (&rebuilt.0, &rebuilt.1, &rebuilt.2),
                (&nodes, &values, &gradients),
            )?;
        }
        (Err(a), Err(b)) => prop_assert_eq!(a.to_string(), b.to_string()),
        (a, b) => prop_assert!(false, "evaluate_into {:?}, fit_into {:?}", a, b),
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn rebuilds_the_bits_of_evaluate_into_in_2d(
        mesh in common::rectangle(), pick in any::<prop::sample::Index>(),
        raw in prop::array::uniform3(0.0f64..1.0),
    ) {
        let s = pick.index(mesh.simplex_count());
        rebuilt_as_evaluated::<2, 3, Linear>(&mesh, s, &raw)?;
        rebuilt_as_evaluated::<2, 6, Quadratic>(&mesh, s, &raw)?;
    }

    #[test]
    fn rebuilds_the_bits_of_evaluate_into_in_3d(
        mesh in common::cuboid(), pick in any::<prop::sample::Index>(),
        raw in prop::array::uniform4(0.0f64..1.0),
    ) {
        let s = pick.index(mesh.simplex_count());
        rebuilt_as_evaluated::<3, 4, Linear>(&mesh, s, &raw)?;
        rebuilt_as_evaluated::<3, 10, Quadratic>(&mesh, s, &raw)?;
    }
}

#[test]
fn the_flat_form_holds_the_inverse_and_the_scale() {
    let inverse = nalgebra::Matrix3::new(1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.5);
    let fit = UmlsFit::<3>::new(&inverse, 0.25);
    let mut flat = [0.0; UmlsFit::<3>::LEN];
    fit.write(&mut flat).unwrap();
    let back = UmlsFit::<3>::read(&flat).unwrap();
    assert_eq!(back, fit);
    assert_eq!(back.inverse(), inverse);
    assert_eq!(back.inv_scale(), 0.25);
    assert!(matches!(
        UmlsFit::<3>::read(&flat[..9]),
        Err(MlsError::InvalidParameter { value, .. }) if value == 9.0
    ));
    assert!(fit.write(&mut [0.0; 11]).is_err());
}

#[test]
fn weights_of_the_wrong_length_are_named_with_the_host() {
    let mesh = umls_mesh::generate::Lattice::new([0.0, 0.0], [1.0, 1.0], [4, 4])
        .triangles(umls_mesh::generate::Diagonal::Right)
        .unwrap();
    let kernel = UmlsKernel::new(&mesh);
    let x = mesh.point_at(5, &Barycentric::from_slice(&[0.5, 0.25, 0.25]).unwrap());
    let ring = mesh.topology().one_ring(5).len();
    let mut weights = vec![0.0; ring + 1];
    let mut scratch = vec![Vector2::zeros(); ring + 1];
    let err = kernel
        .fit_into::<3, Linear>(
            &mesh,
            &located(&mesh, 5, &x),
            &x,
            &mut weights,
            &mut scratch,
        )
        .unwrap_err();
    assert!(
        matches!(err, MlsError::OutputLength { simplex: 5, ring: r, values: v, .. } if r == ring && v == ring + 1)
    );
    let fit = kernel
        .fit_into::<3, Linear>(
            &mesh,
            &located(&mesh, 5, &x),
            &x,
            &mut weights[..ring],
            &mut scratch[..ring],
        )
        .unwrap();
    let err = fit
        .visit::<2, Linear>(&mesh, 5, &x, &weights[..ring - 1], |_, _, _, _| {})
        .unwrap_err();
    assert!(err.to_string().contains("simplex 5"), "{err}");
    let err = fit
        .visit::<2, Linear>(&mesh, 999, &x, &weights[..ring], |_, _, _, _| {})
        .unwrap_err();
    assert!(matches!(err, MlsError::NoSuchSimplex { simplex: 999, .. }));
}
