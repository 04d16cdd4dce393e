//! The legend panel beside a plot: one key per entry (a swatch, or a line in the
//! series' style), its label wrapped at word boundaries, and the font shrunk until every
//! entry fits the panel, so that no entry is ever cut off by the canvas.

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

use super::CHAR_WIDTH;
use super::style::{Style, draw_marker};

/// What an entry's key shows.
#[derive(Debug, Clone, Copy)]
pub(super) enum Key {
    /// A filled square (bar parts, map outcomes).
    Swatch(RGBColor),
    /// A line in a curve's style, with its marker when the curve has markers.
    Line(Style, bool),
}

/// One legend entry.
#[derive(Debug, Clone)]
pub(super) struct Entry {
    pub label: String,
    pub key: Key,
}

/// Left edge of the text: after the key.
const TEXT_X: i32 = 48;
/// Space above the first entry (the plot's caption sits there).
const TOP: i32 = 50;
/// Font sizes tried, largest first.
const FONTS: [u32; 7] = [17, 16, 15, 14, 13, 12, 11];

/// `label` in lines of at most `width` characters, broken at spaces where it can be.
pub(super) fn wrap(label: &str, width: usize) -> Vec<String> {
    let width = width.max(4);
    let mut lines: Vec<String> = Vec::new();
    let mut line = String::new();
    for word in label.split(' ') {
        let mut word = word.to_string();
        loop {
            let joined = if line.is_empty() {
                word.chars().count()
            } else {
                line.chars().count() + 1 + word.chars().count()
            };
            if joined <= width {
                if !line.is_empty() {
                    line.push(' ');
                }
                line.push_str(&word);
                break;
            }
            if !line.is_empty() {
                lines.push(std::mem::take(&mut line));
                continue;
            }
            // A word longer than a line is split where it must be.
            let head: String = word.chars().take(width).collect();
            word = word.chars().skip(width).collect();
            lines.push(head);
            if word.is_empty() {
                break;
            }
        }
    }
    if !line.is_empty() {
        lines.push(line);
    }
    lines
}

/// The largest font whose wrapped entries fit `(width, height)`, with the wrapped lines.
/// When even the smallest font does not fit, each label keeps its first line (cut with
/// "…"), and entries that still find no room are replaced by one line counting them.
fn layout(entries: &[Entry], width: u32, height: u32) -> (u32, Vec<Vec<String>>, bool) {
    let chars =
        |font: u32| ((width as f64 - TEXT_X as f64 - 6.0) / (CHAR_WIDTH * font as f64)) as usize;
    let needed = |font: u32, wrapped: &[Vec<String>]| {
        let lines: usize = wrapped.iter().map(Vec::len).sum();
        TOP as u32 + lines as u32 * (font + 3) + wrapped.len() as u32 * 8
    };
    for font in FONTS {
        let wrapped: Vec<Vec<String>> = entries
            .iter()
            .map(|e| wrap(&e.label, chars(font)))
            .collect();
        if needed(font, &wrapped) <= height {
            return (font, wrapped, false);
        }
    }
    let font = FONTS[FONTS.len() - 1];
    let mut wrapped: Vec<Vec<String>> = entries
        .iter()
        .map(|e| {
            let lines = wrap(&e.label, chars(font));
            let mut first = lines[0].clone();
            if lines.len() > 1 {
                first = first.chars().take(chars(font).saturating_sub(1)).collect();
                first.push('…');
            }
            vec![first]
        })
        .collect();
    if needed(font, &wrapped) > height {
        // Keep the most entries that fit with one more line counting the rest.
        let mut kept = wrapped.len();
        while kept > 0 && needed(font, &wrapped[..kept]) + font + 3 + 8 > height {
            kept -= 1;
        }
        wrapped.truncate(kept);
        wrapped.push(vec![format!("… and {} more", entries.len() - kept)]);
        return (font, wrapped, true);
    }
    (font, wrapped, false)
}

/// Draws `entries` down `area`.
pub(super) fn draw<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[Entry],
) -> std::result::Result<(), String> {
    let (width, height) = area.dim_in_pixel();
    let (font, wrapped, counted) = layout(entries, width, height);
    let line_height = font as i32 + 3;
    let mut y = TOP;
    for (i, (entry, lines)) in entries.iter().zip(&wrapped).enumerate() {
        let middle = y + line_height / 2;
        // The count of entries left out has no key.
        let key = !(counted && i + 1 == wrapped.len());
        match entry.key {
            _ if !key => {}
            Key::Swatch(colour) => area
                .draw(&Rectangle::new(
                    [(10, middle - 8), (40, middle + 8)],
                    colour.filled(),
                ))
                .map_err(|e| e.to_string())?,
            Key::Line(style, markers) => {
                let stroke = style.rgb().stroke_width(3);
                let points = vec![(8, middle), (42, middle)];
                match style.dash.pattern() {
                    None => area.draw(&PathElement::new(points, stroke)),
                    Some((dash, gap)) => {
                        area.draw(&DashedPathElement::new(points, dash, gap, stroke))
                    }
                }
                .map_err(|e| e.to_string())?;
                if markers {
                    draw_marker(area, style.marker, (25, middle), 10, style.rgb())?;
                }
            }
        }
        for line in lines {
            area.draw(&Text::new(
                line.clone(),
                (TEXT_X, y),
                ("sans-serif", font).into_font(),
            ))
            .map_err(|e| e.to_string())?;
            y += line_height;
        }
        y += 8;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_wrap_at_spaces_and_split_long_words() {
        assert_eq!(
            wrap("umls, quadratic-apic-flip:0.99", 14),
            vec!["umls,", "quadratic-apic", "-flip:0.99"]
        );
        assert_eq!(
            wrap("bspline2 (✗ 2 failed)", 40),
            vec!["bspline2 (✗ 2 failed)"]
        );
        for line in wrap("a b c dddddddddddddddddddddd e", 6) {
            assert!(line.chars().count() <= 6, "{line}");
        }
    }

    #[test]
    fn many_long_entries_shrink_the_font_until_they_fit() {
        let entry = |i: usize| Entry {
            label: format!("umls-element-size, quadratic-apic-flip:0.99, variant {i}"),
            key: Key::Swatch(RGBColor(0, 0, 0)),
        };
        let few: Vec<Entry> = (0..2).map(entry).collect();
        let fits = |font: u32, wrapped: &[Vec<String>]| {
            let lines: usize = wrapped.iter().map(Vec::len).sum();
            TOP as u32 + lines as u32 * (font + 3) + wrapped.len() as u32 * 8 <= 480
        };
        let (big, wrapped, _) = layout(&few, 260, 480);
        assert_eq!(big, FONTS[0]);
        assert!(fits(big, &wrapped) && wrapped.len() == 2);
        // Eight long entries fit by shrinking the font, every line kept.
        let eight: Vec<Entry> = (0..8).map(entry).collect();
        let (small, wrapped, counted) = layout(&eight, 260, 480);
        assert!(!counted);
        assert!(small < big && fits(small, &wrapped));
        let words: usize = wrapped.iter().flatten().map(|l| l.split(' ').count()).sum();
        assert_eq!(words, 8 * eight[0].label.split(' ').count());
        // Forty never fit: one line each, the rest counted, and still inside the panel.
        let forty: Vec<Entry> = (0..40).map(entry).collect();
        let (font, wrapped, counted) = layout(&forty, 260, 480);
        assert!(counted);
        assert!(fits(font, &wrapped) && wrapped.len() < 40);
        assert!(wrapped.last().unwrap()[0].starts_with("… and "));
        assert!(wrapped.iter().all(|l| l.len() == 1));
    }
}
