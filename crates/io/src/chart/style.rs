//! How a curve looks: colour, marker and dash. A caller that compares methods gives each
//! method one style and keeps it across every chart, so a reader learns it once; a
//! series without a style takes [`Style::nth`] by its place in the chart.

use plotters::coord::CoordTranslate;
use plotters::prelude::*;

/// The marker drawn at a curve's points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Marker {
    /// A filled circle.
    Circle,
    /// A filled square.
    Square,
    /// A filled upward triangle.
    Triangle,
    /// A filled diamond.
    Diamond,
    /// An open circle.
    Ring,
    /// A plus sign.
    Plus,
}

impl Marker {
    /// Every marker, in the order [`Style::nth`] uses them.
    pub const ALL: [Marker; 6] = [
        Marker::Circle,
        Marker::Square,
        Marker::Triangle,
        Marker::Diamond,
        Marker::Ring,
        Marker::Plus,
    ];
}

/// The line pattern of a curve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Dash {
    /// Unbroken.
    Solid,
    /// Long dashes.
    Dashed,
    /// Dots.
    Dotted,
    /// Short dashes.
    Short,
}

impl Dash {
    /// Every pattern, in the order [`Style::nth`] uses them.
    pub const ALL: [Dash; 4] = [Dash::Solid, Dash::Dashed, Dash::Dotted, Dash::Short];

    /// Dash length and gap in pixels (`None`: solid).
    pub(super) fn pattern(self) -> Option<(u32, u32)> {
        match self {
            Dash::Solid => None,
            Dash::Dashed => Some((12, 6)),
            Dash::Dotted => Some((2, 5)),
            Dash::Short => Some((5, 4)),
        }
    }
}

/// Colours readable on white and distinct from each other (Tableau's 10, then four
/// darker tones), so that no two of the first fourteen styles share a hue.
pub const COLOURS: [(u8, u8, u8); 14] = [
    (31, 119, 180),
    (255, 127, 14),
    (44, 160, 44),
    (214, 39, 40),
    (148, 103, 189),
    (140, 86, 75),
    (227, 119, 194),
    (127, 127, 127),
    (188, 189, 34),
    (23, 190, 207),
    (0, 0, 0),
    (0, 60, 120),
    (128, 0, 0),
    (0, 128, 128),
];

/// A curve's look.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Style {
    /// Stroke and marker colour, RGB.
    pub colour: (u8, u8, u8),
    /// Marker at the points (drawn when the series asks for markers).
    pub marker: Marker,
    /// Line pattern.
    pub dash: Dash,
}

impl Style {
    /// The `i`-th of a sequence of styles in which the first 14 differ in colour and every
    /// one of the first 336 differs from the others in colour, marker or dash.
    pub fn nth(i: usize) -> Self {
        let c = COLOURS.len();
        let m = Marker::ALL.len();
        Self {
            colour: COLOURS[i % c],
            marker: Marker::ALL[(i / c + i % c) % m],
            dash: Dash::ALL[(i / (c * m)) % Dash::ALL.len()],
        }
    }

    pub(super) fn rgb(self) -> RGBColor {
        RGBColor(self.colour.0, self.colour.1, self.colour.2)
    }
}

/// Draws the marker `marker` of `colour`, `size` pixels across, centred at `at` in the
/// coordinates of `area`.
pub(super) fn draw_marker<DB: DrawingBackend, CT: CoordTranslate>(
    area: &DrawingArea<DB, CT>,
    marker: Marker,
    at: CT::From,
    size: i32,
    colour: RGBColor,
) -> std::result::Result<(), String>
where
    CT::From: Clone + 'static,
{
    let r = size / 2;
    let filled = colour.filled();
    let outline = colour.stroke_width(2);
    let polygon =
        |corners: Vec<(i32, i32)>| EmptyElement::at(at.clone()) + Polygon::new(corners, filled);
    match marker {
        Marker::Circle => area.draw(&Circle::new(at.clone(), r, filled)),
        Marker::Ring => area.draw(&Circle::new(at.clone(), r, outline)),
        Marker::Square => area.draw(&polygon(vec![(-r, -r), (r, -r), (r, r), (-r, r)])),
        Marker::Triangle => area.draw(&polygon(vec![(0, -r - 1), (r + 1, r), (-r - 1, r)])),
        Marker::Diamond => area.draw(&polygon(vec![
            (0, -r - 1),
            (r + 1, 0),
            (0, r + 1),
            (-r - 1, 0),
        ])),
        Marker::Plus => area.draw(
            &(EmptyElement::at(at.clone())
                + PathElement::new(vec![(-r, 0), (r, 0)], outline)
                + PathElement::new(vec![(0, -r), (0, r)], outline)),
        ),
    }
    .map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashSet;

    #[test]
    fn the_first_styles_are_all_different() {
        let styles: HashSet<Style> = (0..336).map(Style::nth).collect();
        assert_eq!(styles.len(), 336);
        let colours: HashSet<(u8, u8, u8)> = (0..14).map(|i| Style::nth(i).colour).collect();
        assert_eq!(colours.len(), 14);
    }
}
