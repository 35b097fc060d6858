//! The static generalized forces `R(q) = −K₁(q) + F(q) + B(q)u` (paper eq. 9) and their analytic
//! Jacobian, as the parent module's documentation writes them: the site vectors `y_s` of the
//! elastic, tendon and external terms, projected by `Σ_s Ψ_q,sᵀ y_s`, and the backward pass.

use super::*;

impl<P: StrainParam> Model<P> {
    /// Per-point wrenches `w_i` (local frame) of the external loads and gravity at the current poses;
    /// `wg_i` collects the world-fixed part `[Rᵀm; Rᵀf + W ρA Rᵀ g]` whose derivative is `[m̃; f̃] δθ`,
    /// and the bodies' weights `[c × f_b; f_b]` (their extra derivative is added by
    /// `add_body_weight_offsets`).
    pub(crate) fn point_wrenches(&self, loads: &PreparedLoads, ws: &mut Workspace) {
        for (i, p) in self.disc.points.iter().enumerate() {
            let rt = ws.g[i].rot.transpose();
            let gl = loads.global[i];
            let m = rt * V3::new(gl[0], gl[1], gl[2]);
            let mut f = rt * V3::new(gl[3], gl[4], gl[5]);
            if p.weight > 0.0 {
                f += rt * loads.gravity * (p.weight * self.props[i].ms[3]);
            }
            ws.wg[i] = V6::new(m[0], m[1], m[2], f[0], f[1], f[2]);
            ws.w[i] = loads.local[i] + ws.wg[i];
        }
        // the bodies' weights `[c × f; f]`, world-fixed like gravity (`crate::bodies`)
        for b in &self.bodies {
            let wb = b.weight(&ws.g[b.point].rot.transpose(), &loads.gravity);
            ws.wg[b.point] += wb;
            ws.w[b.point] += wb;
        }
    }

    /// Statics residual `R(q) = −K₁(q) + F(q) + B(q)u` (paper eq. 9) into `r`.
    ///
    /// Also sets `ws.residual_scale = max(‖K₁‖∞, ‖F + Bu‖∞, EI_max)`, the scale of the
    /// convergence test ([`Self::residual_floor`]).
    pub fn statics_residual(
        &self,
        q: &DVector<f64>,
        u: &[f64],
        loads: &PreparedLoads,
        ws: &mut Workspace,
        r: &mut DVector<f64>,
    ) {
        self.forward(q, ws, false);
        self.point_wrenches(loads, ws);
        self.assemble_forces(u, None, ws, r);
    }

    /// Generalized forces `r = −K₁ − D₁ + F + Bu` from the point wrenches already in `ws.w` (after a
    /// forward pass and [`Self::point_wrenches`]); damping `D₁ = Σ W Ψ_qᵀ Ds ξ̇` only if `qd` is given.
    pub(crate) fn assemble_forces(
        &self,
        u: &[f64],
        qd: Option<&DVector<f64>>,
        ws: &mut Workspace,
        r: &mut DVector<f64>,
    ) {
        ws.y.iter_mut().for_each(|y| *y = V6::zeros());
        self.tendon_forces(u, ws, false);
        self.backward(ws, None);
        r.fill(0.0);
        self.project(ws, r);
        let ext = r.amax();
        // elastic (and damping) part, projected separately for the scale
        ws.rtmp.fill(0.0);
        if ws.ev.motion {
            // ξ̇ from the motion evaluation; all sites' wrenches projected in one pass
            ws.ye.iter_mut().for_each(|e| *e = V6::zeros());
            for (i, p) in self.disc.points.iter().enumerate() {
                if p.weight > 0.0 {
                    let mut e = -self.props[i].es.component_mul(&ws.ev.psi[i]) * p.weight;
                    if qd.is_some() {
                        e -= self.props[i].ds.component_mul(&ws.ev.xi_dot[i]) * p.weight;
                    }
                    ws.y[i] += e;
                    ws.ye[i] = e;
                }
            }
            self.param.project(&ws.ye, &mut ws.ev, &mut ws.rtmp);
        } else {
            for (i, p) in self.disc.points.iter().enumerate() {
                if p.weight > 0.0 {
                    let c = self.param.columns(i);
                    let mut e = -self.props[i].es.component_mul(&ws.ev.psi[i]) * p.weight;
                    if let Some(qd) = qd {
                        let xid = ws.ev.psi_q_at(i, &c) * qd.rows(c.start, c.len());
                        e -= self.props[i].ds.component_mul(&xid) * p.weight;
                    }
                    ws.y[i] += e;
                    ws.rtmp.rows_mut(c.start, c.len()).gemv_tr(
                        1.0,
                        &ws.ev.psi_q_at(i, &c),
                        &e,
                        1.0,
                    );
                }
            }
        }
        *r += &ws.rtmp;
        // relative to the forces at play, in whatever units the rod's size gives them (a floor of
        // 1, gvs-spec §8.3, would call a micrometre rod's every state converged), at least the
        // rod's own bending stiffness
        ws.residual_scale = ext.max(ws.rtmp.amax()).max(self.residual_floor());
    }

    /// `r += Σ_s Ψ_q,sᵀ y_s` ([`StrainParam::project`]).
    pub(super) fn project(&self, ws: &mut Workspace, r: &mut DVector<f64>) {
        self.param.project(&ws.y, &mut ws.ev, r);
    }

    /// Tendon forces into `ws.y`; with `jac`, their derivatives into `ws.dyp` (per point 6×n).
    pub(super) fn tendon_forces(&self, u: &[f64], ws: &mut Workspace, jac: bool) {
        let n = self.n_dof();
        for (k, td) in self.tendons.iter().enumerate() {
            let uk = u[k];
            if uk == 0.0 {
                continue;
            }
            let mu = td.friction;

            let mut theta = 0.0;
            let mut tau_prev = V3::zeros();
            if jac {
                ws.dtheta.fill(0.0);
            }
            for (m, &i) in self.tendon_points[k].iter().enumerate() {
                let p = self.disc.points[i];
                let (d, dp) = td.offset_and_rate(p.x);
                let tl = tendon_local(&ws.xi[i], &d, &dp);
                if mu > 0.0 {
                    let rot = ws.g[i].rot;
                    let tau = rot * tl.t;
                    if jac {
                        // δτ = R(−t̃ δθ + ∂t/∂ξ Ψ_q δq), δθ = J_ang δq
                        let c = self.param.columns(i);
                        let rt = rot * tilde(&tl.t);
                        ws.dtau
                            .gemm(-1.0, &rt, &ws.jac.fixed_rows::<3>(0).columns(i * n, n), 0.0);
                        let rdt = rot * tangent_jacobian(&d, &tl);
                        ws.dtau.columns_mut(c.start, c.len()).gemm(
                            1.0,
                            &rdt,
                            &ws.ev.psi_q_at(i, &c),
                            1.0,
                        );
                    }
                    if m > 0 {
                        let x_prev = self.disc.points[self.tendon_points[k][m - 1]].x;
                        let eps = td.smoothing_angle(p.x - x_prev);
                        if jac {
                            let (phi, ga, gb) = smoothed_turning_angle(&tau_prev, &tau, eps);
                            theta += phi;
                            ws.dtheta.gemv_tr(1.0, &ws.dtau_prev, &ga, 1.0);
                            ws.dtheta.gemv_tr(1.0, &ws.dtau, &gb, 1.0);
                        } else {
                            theta += smoothed_turning_angle_value(&tau_prev, &tau, eps);
                        }
                    }
                    tau_prev = tau;
                    if jac {
                        std::mem::swap(&mut ws.dtau, &mut ws.dtau_prev);
                    }
                }
                let weight = self.tendon_weights[k][m];
                if weight == 0.0 {
                    continue;
                }
                let alpha = (-mu * theta).exp();
                let scale = weight * alpha * uk;
                ws.y[i] += tl.phi_a * scale;
                if jac {
                    let c = self.param.columns(i);
                    let bound = if mu > 0.0 { n } else { c.end };
                    ws.dy_hi[i] = ws.dy_hi[i].max(bound);
                    let dphi = wrench_jacobian(&d, &tl) * scale;
                    let mut dy = ws.dyp.columns_mut(self.dy_slot[i] * n, n);
                    // dy[:, c] += ∂Φ/∂ξ Ψ_q column by column (6×6 times 6-vectors; no GEMM call
                    // and its packing buffers per point)
                    let psq = ws.ev.psi_q_at(i, &c);
                    for j in 0..c.len() {
                        let col: V6 = dphi * psq.column(j);
                        let mut d = dy.column_mut(c.start + j);
                        d += col;
                    }
                    if mu > 0.0 {
                        // Φ_a ⊗ ∂α/∂q · W u,  ∂α/∂q = −μ α ∂Θ/∂q
                        dy.ger(-mu * scale, &tl.phi_a, &ws.dtheta, 1.0);
                    }
                }
            }
        }
    }

    /// External forces `Σ J_iᵀ w_i` onto the Magnus sites by the backward pass (spec §8.2); with
    /// `out`, also adds `Σ_s Ψ_q,sᵀ ∂y_s/∂q` of these forces into it.
    ///
    /// `∂y/∂q` of a step (spec §8.2): with `Ū ← coAd (Ū + C_w J_{i+1})` (`C_w = coadbar(w) +
    /// [m̃_g 0; f̃_g 0]`, the last term the derivative of world-fixed loads, spec §7.5) and
    /// `t = Ū − coadbar(F̄) J_i`, `dv = Tᵀ t + ∂(TᵀF̄)/∂Ω Z`, and (Z4)
    /// `dy₁ = (h/2 + k coad_{ξ₂}) dv + k coadbar(v) Ψ_q2`, `dy₂ = (h/2 − k coad_{ξ₁}) dv − k coadbar(v) Ψ_q1`.
    /// Hence `Ψ_q1ᵀ dy₁ + Ψ_q2ᵀ dy₂ = G t + (local terms on the step's columns c)` with the
    /// `|c| × 6` matrix `G = (Ψ_q1ᵀ A₁ + Ψ_q2ᵀ A₂) Tᵀ`: one pass over the columns where `Ū` or
    /// `J_i` is non-zero adds `G t_j` to rows `c` of column j.
    pub(super) fn backward(&self, ws: &mut Workspace, mut out: Option<&mut DMatrix<f64>>) {
        let n = self.n_dof();
        let mut fbar = V6::zeros();
        let mut ub = 0; // Ū is zero at columns >= ub
        if out.is_some() {
            ws.ubar.fill(0.0);
        }
        for i in (0..self.disc.n_points() - 1).rev() {
            let w1 = ws.w[i + 1];
            fbar += w1;
            // C_w J_{i+1} is added to Ū on the columns < h1
            let h1 = match out.is_some() && w1 != V6::zeros() {
                true => ws.jac_hi[i + 1],
                false => 0,
            };
            ub = ub.max(h1);
            let Some(st) = self.disc.steps[i] else {
                for j in 0..h1 {
                    let jj = ws
                        .jac
                        .column((i + 1) * n + j)
                        .fixed_rows::<6>(0)
                        .into_owned();
                    let mut u = ws.ubar.fixed_columns_mut::<1>(j);
                    u += load_derivative_mul(&w1, &ws.wg[i + 1], &jj);
                }
                continue;
            };
            let et = &ws.et[i];
            fbar = et.g.coadjoint_mul(&fbar);
            let v = et.t_tr_mul(&fbar);
            let h = st.h;
            let [s1, s2] = st.sites;
            let k = ZANNA_C * h * h;
            match self.disc.order {
                MagnusOrder::Z4 => {
                    ws.y[s1] += v * (0.5 * h) + coad_mul(&ws.xi[s2], &v) * k;
                    ws.y[s2] += v * (0.5 * h) - coad_mul(&ws.xi[s1], &v) * k;
                }
                MagnusOrder::Z2 => ws.y[s1] += v * h,
            }
            let Some(out) = out.as_deref_mut() else {
                continue;
            };
            let c = self.param.columns(s1);
            let nc = c.len();
            let hj = if fbar == V6::zeros() { 0 } else { ws.jac_hi[i] };
            let tb = ub.max(hj);
            // The step's 6×6 maps, as matrices where they serve many columns (a matrix–vector
            // product is the cheapest per column), by their 6-vector products otherwise (a reduced
            // model's step has one or two columns: forming the matrices would cost more).
            // A₁ = h/2 + k coad_ξ₂, A₂ = h/2 − k coad_ξ₁ (Z2: A₁ = h, A₂ = 0), coadᵀ = −ad.
            let (xi1, xi2) = (ws.xi[s1], ws.xi[s2]);
            let z4 = self.disc.order == MagnusOrder::Z4;
            let local_maps = if nc > STEP_MATRIX_COLUMNS {
                let (a1, a2) = match z4 {
                    true => (
                        M6::identity() * (0.5 * h) + coad(&xi2) * k,
                        M6::identity() * (0.5 * h) - coad(&xi1) * k,
                    ),
                    false => (M6::identity() * h, M6::zeros()),
                };
                let cbv = if z4 { coadbar(&v) * k } else { M6::zeros() };
                LocalMaps::Matrices {
                    a1,
                    a2,
                    cbv,
                    d: et.d_ttf(&fbar),
                }
            } else {
                LocalMaps::Products(et.d_ttf_vectors(&fbar))
            };
            let sweep_mats = (tb.max(c.end) > STEP_MATRIX_COLUMNS).then(|| {
                (
                    et.g.adjoint_inv().transpose(),
                    coadbar(&fbar),
                    load_derivative(&w1, &ws.wg[i + 1]),
                )
            });
            // H = [G | Ψ_q1ᵀ | Ψ_q2ᵀ] (|c| × 18, column-major in gbuf), Gᵀ = T (A₁ᵀ Ψ_q1 + A₂ᵀ Ψ_q2)
            {
                let (p1, p2) = (ws.ev.psi_q_at(s1, &c), ws.ev.psi_q_at(s2, &c));
                let lt = match &local_maps {
                    LocalMaps::Matrices { a1, a2, .. } => Some((a1.transpose(), a2.transpose())),
                    LocalMaps::Products(_) => None,
                };
                for r in 0..nc {
                    let (p1r, p2r): (V6, V6) =
                        (p1.column(r).into_owned(), p2.column(r).into_owned());
                    let atp = match (&lt, z4) {
                        (Some((a1t, a2t)), _) => a1t * p1r + a2t * p2r,
                        (None, true) => {
                            (p1r + p2r) * (0.5 * h) + (ad_mul(&xi1, &p2r) - ad_mul(&xi2, &p1r)) * k
                        }
                        (None, false) => p1r * h,
                    };
                    // (T formed on a wide step, see forward_jacobians)
                    let g = match lt {
                        Some(_) => et.t * atp,
                        None => et.t_mul(&atp),
                    };
                    for a in 0..6 {
                        ws.gbuf[a * nc + r] = g[a];
                        ws.gbuf[(6 + a) * nc + r] = p1r[a];
                        ws.gbuf[(12 + a) * nc + r] = p2r[a];
                    }
                }
            }
            // Local terms on the step's columns (j ∈ c): Ψ_q1ᵀ x₁ + Ψ_q2ᵀ x₂ with
            // x₁ = A₁ D Z_j + k coadbar(v) Ψ_q2,j, x₂ = A₂ D Z_j − k coadbar(v) Ψ_q1,j
            // (D = ∂(TᵀF̄)/∂Ω; Z2: no coadbar term; coadbar(v) p = coad_p v).
            let local = |zj: &V6, p1j: &V6, p2j: &V6| -> (V6, V6) {
                match &local_maps {
                    LocalMaps::Matrices { a1, a2, cbv, d } => {
                        let dz = d * zj;
                        (a1 * dz + cbv * p2j, a2 * dz - cbv * p1j)
                    }
                    LocalMaps::Products(dv) => {
                        let dz = dv.mul(zj);
                        match z4 {
                            true => (
                                dz * (0.5 * h) + (coad_mul(&xi2, &dz) + coad_mul(p2j, &v)) * k,
                                dz * (0.5 * h) - (coad_mul(&xi1, &dz) + coad_mul(p1j, &v)) * k,
                            ),
                            false => (dz * h, V6::zeros()),
                        }
                    }
                }
            };
            // one pass: Ū_j ← coAd (Ū_j + C_w J_{i+1,j}); t = Ū_j − coadbar(F̄) J_{i,j};
            // out[c, j] += G t (+ the local terms)
            let hm = &ws.gbuf[..18 * nc];
            let zi = ws.z.columns(i * n, n);
            let wg1 = ws.wg[i + 1];
            for j in 0..tb.max(c.end) {
                let mut t = V6::zeros();
                if j < ub {
                    let mut u: V6 = ws.ubar.fixed_columns::<1>(j).into_owned();
                    if j < h1 {
                        let jj: V6 = ws.jac.fixed_columns::<1>((i + 1) * n + j).into_owned();
                        u += match &sweep_mats {
                            Some((_, _, cw)) => cw * jj,
                            None => load_derivative_mul(&w1, &wg1, &jj),
                        };
                    }
                    u = match &sweep_mats {
                        Some((coadj, _, _)) => coadj * u,
                        None => et.g.coadjoint_mul(&u),
                    };
                    ws.ubar.fixed_columns_mut::<1>(j).copy_from(&u);
                    t = u;
                }
                if j < hj {
                    let jj: V6 = ws.jac.fixed_columns::<1>(i * n + j).into_owned();
                    t -= match &sweep_mats {
                        Some((_, bf, _)) => bf * jj,
                        None => coad_mul(&jj, &fbar),
                    };
                }
                if c.contains(&j) {
                    let zj: V6 = zi.fixed_columns::<1>(j).into_owned();
                    let p1j: V6 = ws.ev.psi_q_at(s1, &c).column(j - c.start).into_owned();
                    let p2j: V6 = ws.ev.psi_q_at(s2, &c).column(j - c.start).into_owned();
                    let (x1, x2) = local(&zj, &p1j, &p2j);
                    add_h_times(out, &c, j, hm, &t, &x1, &x2);
                } else if j < tb {
                    add_g_times(out, &c, j, &hm[..6 * nc], &t);
                }
            }
        }
    }

    /// `jac += J_angᵀ E J_ang` at each body's point, `E = f̃ c̃`: the derivative of an off-centre
    /// body's weight moment `c × f` beyond the world-fixed kernel of the backward pass
    /// ([`crate::bodies`]).
    fn add_body_weight_offsets(
        &self,
        loads: &PreparedLoads,
        ws: &Workspace,
        jac: &mut DMatrix<f64>,
    ) {
        let n = self.n_dof();
        for b in &self.bodies {
            let h = ws.jac_bound(b.point);
            if h == 0 || b.body.center == [0.0; 3] || loads.gravity == V3::zeros() {
                continue;
            }
            let e = b.weight_offset_derivative(&ws.g[b.point].rot.transpose(), &loads.gravity);
            let ja = ws.jac.fixed_rows::<3>(0);
            for c in 0..h {
                let ejc: V3 = e * ja.column(b.point * n + c);
                for r in 0..h {
                    jac[(r, c)] += ja.column(b.point * n + r).dot(&ejc);
                }
            }
        }
    }

    /// Analytic statics Jacobian `∂R/∂q` (spec §8.2, with `∂α/∂q` of friction) into `jac`.
    pub fn statics_jacobian(
        &self,
        q: &DVector<f64>,
        u: &[f64],
        loads: &PreparedLoads,
        ws: &mut Workspace,
        jac: &mut DMatrix<f64>,
    ) {
        self.forward(q, ws, false);
        self.statics_jacobian_after_forward(q, u, loads, ws, jac);
    }

    /// [`Self::statics_jacobian`] when the last evaluation with `ws` was a forward pass at this same
    /// `q` (e.g. [`Self::statics_residual`] at the point where the solver now wants `∂R/∂q`): the
    /// strains, poses and Magnus steps are reused, only the Jacobians are added.
    pub fn statics_jacobian_after_forward(
        &self,
        q: &DVector<f64>,
        u: &[f64],
        loads: &PreparedLoads,
        ws: &mut Workspace,
        jac: &mut DMatrix<f64>,
    ) {
        let n = self.n_dof();
        self.forward_jacobians(ws);
        self.point_wrenches(loads, ws);
        ws.y.iter_mut().for_each(|y| *y = V6::zeros());
        for (i, hi) in ws.dy_hi.iter_mut().enumerate() {
            if *hi > 0 {
                ws.dyp.columns_mut(self.dy_slot[i] * n, *hi).fill(0.0);
                *hi = 0;
            }
        }
        // elastic: −K (linear), or −Σ W Ψ_qᵀ Es Ψ_q on each point's columns
        match &self.k_lin {
            Some(k) => jac.zip_apply(k, |a, b| *a = -b),
            None => {
                jac.fill(0.0);
                for (i, p) in self.disc.points.iter().enumerate() {
                    if p.weight > 0.0 {
                        let c = self.param.columns(i);
                        let psq = ws.ev.psi_q_at(i, &c);
                        let mut e = ws.t1.columns_mut(0, c.len());
                        for a in 0..6 {
                            let es = -self.props[i].es[a] * p.weight;
                            for j in 0..c.len() {
                                e[(a, j)] = es * psq[(a, j)];
                            }
                        }
                        jac.view_mut((c.start, c.start), (c.len(), c.len()))
                            .gemm_tr(1.0, &psq, &e, 1.0);
                    }
                }
            }
        }
        for (i, p) in self.disc.points.iter().enumerate() {
            if p.weight > 0.0 {
                ws.y[i] -= self.props[i].es.component_mul(&ws.ev.psi[i]) * p.weight;
            }
        }
        // tendons: Ψ_qᵀ ∂y_i/∂q at the points they reach
        self.tendon_forces(u, ws, true);
        for i in 0..self.disc.n_points() {
            let hi = ws.dy_hi[i];
            if hi == 0 {
                continue;
            }
            let c = self.param.columns(i);
            let mut g = DMatrixViewMut::from_slice(&mut ws.gbuf[..6 * c.len()], c.len(), 6);
            g.tr_copy_from(&ws.ev.psi_q_at(i, &c));
            let dy = ws.dyp.columns(self.dy_slot[i] * n, hi);
            for j in 0..hi {
                let t: V6 = dy.fixed_columns::<1>(j).into_owned();
                add_g_times(jac, &c, j, &ws.gbuf[..6 * c.len()], &t);
            }
        }
        self.backward(ws, Some(jac));
        self.add_body_weight_offsets(loads, ws, jac);
        if !self.param.is_linear() {
            self.param.add_weighted_hessian(q, &ws.y, &mut ws.ev, jac);
        }
    }
}
