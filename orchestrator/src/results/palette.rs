//! One look for every agent in every figure: `errors.svg`, the 3D view
//! (`view.html`, its data carries these) and `Run.plot()` in Python (the
//! native module exports them).
//!
//! Agent `k` (0-based, in id order) is drawn in [`COLOURS`]`[k mod 7]` with
//! the dash pattern [`DASHES`]`[(k div 7) mod 4]`: the colours are Paul
//! Tol's *bright* qualitative scheme, told apart under the common colour
//! vision deficiencies and readable on white and on the view's dark
//! background; with the dashes, 28 agents are drawn each in a look of its
//! own (more are drawn as their band, `envelope.rs`).

use plotters::style::RGBColor;

/// Paul Tol's *bright* scheme: blue, red, green, yellow, cyan, purple, grey.
pub const COLOURS: [&str; 7] = [
    "#4477AA", "#EE6677", "#228833", "#CCBB44", "#66CCEE", "#AA3377", "#BBBBBB",
];

/// Dash patterns as (drawn, gap) in px at a 2 px line; `(0, 0)`: solid.
pub const DASHES: [(u32, u32); 4] = [(0, 0), (9, 4), (2, 3), (16, 6)];

/// The colour of agent `k` as `#RRGGBB`.
#[must_use]
pub fn colour_hex(k: usize) -> &'static str {
    COLOURS[k % COLOURS.len()]
}

/// The colour of agent `k`.
#[must_use]
pub fn colour(k: usize) -> RGBColor {
    let hex = colour_hex(k);
    let byte = |i: usize| u8::from_str_radix(&hex[i..i + 2], 16).unwrap_or(0);
    RGBColor(byte(1), byte(3), byte(5))
}

/// The dash pattern of agent `k` (`None`: solid).
#[must_use]
pub fn dash(k: usize) -> Option<(u32, u32)> {
    let d = DASHES[(k / COLOURS.len()) % DASHES.len()];
    (d.0 > 0).then_some(d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn twenty_eight_agents_each_have_a_look_of_their_own() {
        let looks: std::collections::BTreeSet<(&str, Option<(u32, u32)>)> =
            (0..28).map(|k| (colour_hex(k), dash(k))).collect();
        assert_eq!(looks.len(), 28);
        assert_eq!(colour(1), RGBColor(0xEE, 0x66, 0x77));
        assert_eq!((dash(0), dash(7)), (None, Some((9, 4))));
    }
}
