//! The exact active-set solver agrees with clarabel (tight tolerances) to
//! 1e-6 on random ridge / box-constrained least-squares problems.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, NonnegativeConeT, SolverStatus,
};
use hil_workload::features::SparseRow;
use hil_workload::fit::{BoxLsq, Gram};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn clarabel_solve(p: &BoxLsq<'_>) -> Vec<f64> {
    let k = p.gram.k;
    // P: upper triangle of G + diag(ρ), column-major
    let (mut colptr, mut rowval, mut nzval) = (vec![0], Vec::new(), Vec::new());
    for j in 0..k {
        for i in 0..=j {
            let v = p.gram.g[i * k + j] + if i == j { p.ridge[i] } else { 0.0 };
            if v != 0.0 {
                rowval.push(i);
                nzval.push(v);
            }
        }
        colptr.push(rowval.len());
    }
    let pm = CscMatrix::new(k, k, colptr, rowval, nzval);
    let q: Vec<f64> = p.gram.b.iter().map(|b| -b).collect();
    // constraints A x + s = b, s ≥ 0: -x ≤ -l and x ≤ u for finite bounds
    let mut rows: Vec<(usize, f64, f64)> = Vec::new(); // (var, coef, rhs)
    for i in 0..k {
        if p.lower[i].is_finite() {
            rows.push((i, -1.0, -p.lower[i]));
        }
        if p.upper[i].is_finite() {
            rows.push((i, 1.0, p.upper[i]));
        }
    }
    let m = rows.len();
    let (mut colptr, mut rowval, mut nzval) = (vec![0], Vec::new(), Vec::new());
    for j in 0..k {
        for (r, (var, coef, _)) in rows.iter().enumerate() {
            if *var == j {
                rowval.push(r);
                nzval.push(*coef);
            }
        }
        colptr.push(rowval.len());
    }
    let a = CscMatrix::new(m, k, colptr, rowval, nzval);
    let b: Vec<f64> = rows.iter().map(|r| r.2).collect();
    let cones = if m > 0 {
        vec![NonnegativeConeT(m)]
    } else {
        vec![]
    };
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .tol_gap_abs(1e-12)
        .tol_gap_rel(1e-12)
        .tol_feas(1e-12)
        .tol_ktratio(1e-10)
        .max_iter(500)
        .build()
        .unwrap();
    let mut solver = DefaultSolver::new(&pm, &q, &a, &b, &cones, settings).unwrap();
    solver.solve();
    assert!(
        matches!(
            solver.solution.status,
            SolverStatus::Solved | SolverStatus::AlmostSolved
        ),
        "{:?}",
        solver.solution.status
    );
    solver.solution.x.clone()
}

#[test]
fn active_set_matches_clarabel() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for case in 0..40 {
        let k = rng.random_range(2..9);
        let n = k + rng.random_range(5..40);
        let mut g = Gram::new(k);
        let truth: Vec<f64> = (0..k).map(|_| rng.random_range(-1.0..1.0)).collect();
        for _ in 0..n {
            let x: Vec<f64> = (0..k).map(|_| rng.random_range(-1.0..1.0)).collect();
            let y = x.iter().zip(&truth).map(|(a, b)| a * b).sum::<f64>()
                + 0.3 * rng.random_range(-1.0..1.0);
            g.add_row(&SparseRow {
                entries: x.into_iter().enumerate().collect(),
                y,
            });
        }
        let mut p = BoxLsq::plain(&g);
        for i in 0..k {
            match (case + i) % 4 {
                0 => {}
                1 => p.lower[i] = 0.0,
                2 => {
                    p.lower[i] = 0.05;
                    p.upper[i] = 1.0;
                }
                _ => p.upper[i] = 0.1,
            }
            if case % 2 == 1 {
                p.ridge[i] = 10f64.powi(rng.random_range(-3..3));
            }
        }
        let ours = p.solve(None).unwrap();
        let theirs = clarabel_solve(&p);
        for (a, b) in ours.iter().zip(&theirs) {
            assert!(
                (a - b).abs() < 1e-6,
                "case {case}: ours {ours:?} clarabel {theirs:?}"
            );
        }
        // ours is at least as good (it is exact)
        assert!(
            p.objective(&ours) <= p.objective(&theirs) + 1e-9,
            "case {case}"
        );
    }
}
