//! The paper's published numbers (`../shared/paper/ae-strain-rom-paper.md`), printed beside ours.
//! Each constant names the table, figure or sentence it comes from.

/// Table I: RMS reconstruction error over the full dataset; rows 3, 5, 7 hidden layers, columns
/// r = 1, 2, 3. Single-cable manipulator (IV-A).
pub const TABLE_I_IV_A: [[f64; 3]; 3] = [
    [0.1447, 0.0936, 0.0870],
    [0.0556, 0.0336, 0.0321],
    [0.0383, 0.0310, 0.0248],
];

/// Table I, soft beam under external moment (IV-B).
pub const TABLE_I_IV_B: [[f64; 3]; 3] = [
    [7.6686, 2.6016, 1.5544],
    [6.4376, 0.8733, 0.6452],
    [4.8100, 0.5923, 0.5318],
];

/// The hidden-layer counts of Table I's rows.
pub const TABLE_I_LAYERS: [usize; 3] = [3, 5, 7];

/// A Table III row: POD and AE DOF (same-accuracy rows) or errors in % of the length (same-DOF
/// rows), their times and the HOM's time \[s\].
#[derive(Debug, Clone, Copy)]
pub struct TableIiiRow {
    pub pod_dof: usize,
    pub ae_dof: usize,
    /// Same-DOF rows: tip error, % of the length.
    pub pod_error: Option<f64>,
    pub ae_error: Option<f64>,
    pub pod_time_s: f64,
    pub ae_time_s: f64,
    pub hom_time_s: f64,
}

/// Table III, IV-A (same accuracy, < 1 % strain error).
pub const TABLE_III_IV_A: TableIiiRow = TableIiiRow {
    pod_dof: 7,
    ae_dof: 1,
    pod_error: None,
    ae_error: None,
    pod_time_s: 0.165,
    ae_time_s: 0.042,
    hom_time_s: 0.670,
};

/// Table III, IV-B (same accuracy).
pub const TABLE_III_IV_B: TableIiiRow = TableIiiRow {
    pod_dof: 19,
    ae_dof: 2,
    pod_error: None,
    ae_error: None,
    pod_time_s: 0.239,
    ae_time_s: 0.037,
    hom_time_s: 0.810,
};

/// Table III, IV-C1 (same DOF: 6; tip error % of the length).
pub const TABLE_III_IV_C1: TableIiiRow = TableIiiRow {
    pod_dof: 6,
    ae_dof: 6,
    pod_error: Some(8.3),
    ae_error: Some(3.9),
    pod_time_s: 0.094,
    ae_time_s: 0.106,
    hom_time_s: 0.276,
};

/// Section IV-C1 (text): mean tip errors of the 6-DOF ROMs against the HOM at the five test inputs
/// \[cm\]: AE-ROM 2.32 cm (3.9 % L), POD-ROM 4.95 cm (8.3 % L).
pub const IV_C1_AE_TIP_ERROR_CM: f64 = 2.32;
pub const IV_C1_POD_TIP_ERROR_CM: f64 = 4.95;

/// Section IV-C: DOF of the six-tendon manipulator's HOM (two divisions, Legendre bases).
pub const IV_C_HOM_DOF: usize = 28;

/// Table III, IV-C2 (same DOF: 7; mean tip error over the 10 s test).
pub const TABLE_III_IV_C2: TableIiiRow = TableIiiRow {
    pod_dof: 7,
    ae_dof: 7,
    pod_error: Some(7.0),
    ae_error: Some(1.9),
    pod_time_s: 11.6,
    ae_time_s: 17.2,
    hom_time_s: 114.3,
};

/// Section IV-C2 (text): the AE-ROMs' mean tip error is up to 80 % below the POD-ROMs' of equal
/// DOF ("reductions in average errors of up to 80%"), as a fraction.
pub const IV_C2_MAX_ERROR_REDUCTION: f64 = 0.80;

/// Section V: the prototype's tensions \[N\].
pub const V_TENSIONS: [f64; 4] = [-1.12, -2.35, -3.7, -5.05];

/// Section V: tip errors against the *measured* tip positions, [mean, max] in cm and in % of the
/// 25 cm length: AE-ROM r = 1 and POD-ROM r = 1.
pub const V_AE_ERROR_CM: [f64; 2] = [0.87, 1.43];
pub const V_AE_ERROR_PERCENT: [f64; 2] = [3.48, 5.72];
pub const V_POD_ERROR_CM: [f64; 2] = [4.76, 6.42];
pub const V_POD_ERROR_PERCENT: [f64; 2] = [19.04, 25.68];
