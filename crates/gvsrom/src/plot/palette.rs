//! The paper's colours (Fig. 7: HOM green, AE gold, POD red; Fig. 10: AE blue) and eight further
//! colours, distinct from those and from each other, for series without a colour of their own.

use super::Rgb;

/// High-order model (ground truth): green.
pub const HOM: Rgb = Rgb(34, 139, 34);
/// Autoencoder ROM: gold.
pub const AE: Rgb = Rgb(222, 160, 0);
/// POD ROM: red.
pub const POD: Rgb = Rgb(214, 39, 40);
/// A blue for a second ROM of a kind in the same chart (e.g. the POD ROM at matched accuracy beside the
/// POD ROM at equal DOFs), or for the AE where the paper draws it blue (Fig. 10).
pub const POD_ALT: Rgb = Rgb(31, 119, 180);
/// The AE in blue, as in the paper's Fig. 10 (the same colour as [`POD_ALT`]).
pub const AE_ALT: Rgb = POD_ALT;
/// Further distinct colours, in the order series without a colour take them.
pub const EXTRA: [Rgb; 8] = [
    Rgb(31, 119, 180),  // blue
    Rgb(255, 127, 14),  // orange
    Rgb(148, 103, 189), // purple
    Rgb(140, 86, 75),   // brown
    Rgb(23, 190, 207),  // cyan
    Rgb(227, 119, 194), // pink
    Rgb(127, 127, 127), // grey
    Rgb(188, 189, 34),  // olive
];
