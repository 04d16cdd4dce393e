//! One look per kernel, the same in every chart of the report: the paper's kernel and
//! the established ones in solid lines and colours of their own, UMLS's variants in
//! dashed and dotted lines, so a reader learns the key once. A kernel the table does not
//! know (a user's own) is left to the chart, which gives it a style no other series of
//! the panel has.

use umls_io::chart::{COLOURS, Dash, Marker, Style};

/// The kernels with a fixed style: name, colour index into [`COLOURS`], marker, dash.
const KERNEL_STYLES: [(&str, usize, Marker, Dash); 14] = [
    ("umls", 0, Marker::Circle, Dash::Solid),
    ("linear-fe", 1, Marker::Square, Dash::Solid),
    ("bspline2", 2, Marker::Triangle, Dash::Solid),
    ("bspline3", 3, Marker::Diamond, Dash::Solid),
    ("ugimp", 4, Marker::Ring, Dash::Solid),
    ("umls-eta4", 5, Marker::Square, Dash::Dashed),
    ("umls-eta8", 6, Marker::Triangle, Dash::Dashed),
    ("umls-element-size", 7, Marker::Diamond, Dash::Dashed),
    ("umls-wide", 8, Marker::Ring, Dash::Dashed),
    ("umls-full-gradient", 9, Marker::Plus, Dash::Dashed),
    ("umls-frozen-eta", 10, Marker::Square, Dash::Dotted),
    ("umls-uncorrected", 11, Marker::Triangle, Dash::Dotted),
    ("umls-sharp", 12, Marker::Diamond, Dash::Short),
    ("umls-quadratic", 13, Marker::Ring, Dash::Short),
];

/// The fixed style of `kernel`, if it has one.
pub fn kernel_style(kernel: &str) -> Option<Style> {
    KERNEL_STYLES
        .iter()
        .find(|(name, ..)| *name == kernel)
        .map(|&(_, colour, marker, dash)| Style {
            colour: COLOURS[colour],
            marker,
            dash,
        })
}

/// The kernels whose style is fixed, in legend order.
pub fn styled_kernels() -> impl Iterator<Item = &'static str> {
    KERNEL_STYLES.iter().map(|(name, ..)| *name)
}

/// `styles` with repeats made distinct: a later series whose style an earlier one of
/// the panel already has (the same kernel on another thread count, say) keeps its colour
/// and takes the next dash and marker not in use.
pub fn distinct(styles: &[Option<Style>]) -> Vec<Option<Style>> {
    let mut used: Vec<Style> = Vec::new();
    styles
        .iter()
        .map(|style| {
            let mut style = (*style)?;
            let mut turn = 0;
            while used.contains(&style) && turn < Dash::ALL.len() * Marker::ALL.len() {
                turn += 1;
                style.dash = Dash::ALL[turn % Dash::ALL.len()];
                style.marker = Marker::ALL[(turn / Dash::ALL.len() + turn) % Marker::ALL.len()];
            }
            used.push(style);
            Some(style)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashSet;

    #[test]
    fn every_styled_kernel_looks_different() {
        let styles: Vec<Style> = styled_kernels().filter_map(kernel_style).collect();
        assert_eq!(styles.len(), KERNEL_STYLES.len());
        let colours: HashSet<_> = styles.iter().map(|s| s.colour).collect();
        assert_eq!(colours.len(), styles.len(), "one colour per kernel");
        assert_eq!(kernel_style("my-kernel"), None);
    }

    #[test]
    fn repeated_styles_are_made_distinct() {
        let umls = kernel_style("umls");
        let styles = distinct(&[umls, umls, umls, None, kernel_style("bspline2")]);
        let set: HashSet<_> = styles.iter().flatten().collect();
        assert_eq!(set.len(), 4);
        assert_eq!(styles[0], umls);
        assert_eq!(styles[1].map(|s| s.colour), umls.map(|s| s.colour));
        assert_eq!(styles[3], None);
    }
}
