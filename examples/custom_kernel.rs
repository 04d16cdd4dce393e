//! A kernel of your own (linear hats on a grid) runs built-in scenes through the runner.
use nalgebra::SVector;
use umls::runner::{KernelFactory, RunError, RunOptions, Scene, Setup, run_with};
use umls::transfer::{Kernel, KernelError, Stencil};
/// Linear hats on the grid of spacing `h` from `lower`, `n` nodes per axis.
#[rustfmt::skip] // the whole kernel on one screen
struct Tent<const D: usize> { lower: SVector<f64, D>, h: f64, n: [usize; D] }
#[rustfmt::skip]
impl<const D: usize> Kernel<D> for Tent<D> {
    type Cache = ();
    fn node_count(&self) -> usize { self.n.iter().product() }
    fn spacing(&self) -> f64 { self.h }
    fn node_position(&self, node: usize) -> SVector<f64, D> {
        let mut rest = node;
        self.lower + SVector::from_fn(|k, _| { let i = rest % self.n[k]; rest /= self.n[k]; i as f64 * self.h })
    }
    fn stencil(&self, x: &SVector<f64, D>, _: &mut (), out: &mut Stencil<D>) -> Result<(), KernelError> {
        let s = (x - self.lower) / self.h; // the cell's corner node is s.floor() on each axis
        let inside = (0..D).all(|k| s[k] >= 0.0 && s[k] < (self.n[k] - 1) as f64);
        if !inside { return Err(KernelError::OutsideDomain { point: x.iter().copied().collect() }) }
        out.clear();
        for corner in 0..1usize << D {
            let (mut node, mut stride, mut w, mut grad) = (0, 1, 1.0, SVector::<f64, D>::repeat(1.0));
            for k in 0..D {
                let (bit, f) = ((corner >> k) & 1, s[k] - s[k].floor());
                let (wk, dk) = if bit == 1 { (f, 1.0 / self.h) } else { (1.0 - f, -1.0 / self.h) };
                node += (s[k].floor() as usize + bit) * stride;
                stride *= self.n[k];
                w *= wk;
                grad = SVector::from_fn(|j, _| grad[j] * if j == k { dk } else { wk });
            }
            out.push(node as u32, w, grad, self.node_position(node) - x);
        }
        Ok(())
    }
}
/// Builds the grid over the scene's box at its lattice spacing, one cell of margin.
struct TentFactory;
#[rustfmt::skip]
impl<const D: usize> KernelFactory<D> for TentFactory {
    type Kernel = Tent<D>;
    fn name(&self) -> String { "tent".into() }
    fn on_mesh(&self) -> bool { false }
    fn build(&self, scene: &Scene, setup: &Setup<D>) -> Result<Tent<D>, RunError> {
        let h = setup.lattice_spacing.ok_or_else(|| scene.value_error("mesh", "tent needs a lattice"))?;
        let (lower, upper) = setup.background.bounding_box();
        let n = std::array::from_fn(|k| ((upper[k] - lower[k]) / h).round() as usize + 3);
        Ok(Tent { lower: lower.add_scalar(-h), h, n })
    }
}
fn main() -> Result<(), RunError> {
    let options = RunOptions::default(); // every core, no files: the report has it all
    let bar = run_with::<1, _>(&Scene::load("vibrating-bar")?, &options, &TentFactory)?;
    let disks = run_with::<2, _>(&Scene::load("colliding-disks")?, &options, &TentFactory)?;
    for s in [bar.summary, disks.summary] {
        println!("{} with {}: {}", s.scene, s.kernel, s.to_json()["metrics"]);
    }
    Ok(())
}
