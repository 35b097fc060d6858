//! `DecoderMap`'s `CoefficientMap` calls allocate nothing (the map.rs contract), nor those of the
//! same map scaled by `z₁` (`ScaledMap`, a scaled autoencoder's decoder), checked with a counting
//! global allocator in this test binary.

use gvs::inputs::SplitMix64;
use rom::map::CoefficientMap;
use rom::nn::{DecoderMap, Mlp, ScaledMap, Scaling};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

// SAFETY: forwards to the system allocator; only counts calls on the current thread.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.with(|a| a.set(a.get() + 1));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Every call of `map` (r = 3, m = 5) once, after a first `eval`; returns the allocations counted.
fn allocations_of_every_call(map: &impl CoefficientMap) -> usize {
    let (r, m) = (3, 5);
    let (z, zd, g) = (vec![0.3, -0.2, 0.5], vec![1.0, 0.5, -0.4], vec![0.1; m]);
    let (mut c, mut c_z, mut c_z_dot) = (vec![0.0; m], vec![0.0; m * r], vec![0.0; m * r]);
    let (mut hess, mut scratch) = (vec![0.0; r * r], vec![0.0; map.scratch_len()]);
    let (mut c_dot, mut c_acc, mut back) = (vec![0.0; m], vec![0.0; m], vec![0.0; r]);
    let before = ALLOCATIONS.with(Cell::get);
    map.eval(&z, &mut c, &mut c_z, &mut scratch);
    map.eval_rate(&z, &zd, &mut c_z_dot, &mut scratch);
    map.add_weighted_hessian(&z, &g, &mut hess, &mut scratch);
    map.eval_motion(
        &z,
        &zd,
        Some(&zd),
        &mut c,
        &mut c_dot,
        &mut c_acc,
        &mut scratch,
    );
    map.vjp(&g, &mut back, &mut scratch);
    map.eval_value(&z, &mut c, &mut scratch);
    let counted = ALLOCATIONS.with(Cell::get) - before;
    assert!(c
        .iter()
        .chain(&c_z)
        .chain(&c_z_dot)
        .chain(&hess)
        .all(|v| v.is_finite()));
    counted
}

#[test]
fn no_evaluation_of_a_decoder_allocates() {
    let (r, n, m) = (3, 40, 5);
    let mut rng = SplitMix64::new(9);
    let decoder = Mlp::glorot(&[r, 10, 20, n], &mut rng).unwrap();
    let a: Vec<f64> = (0..m * n).map(|_| rng.range(-1.0, 1.0)).collect();
    let map = DecoderMap::new(&decoder, &Scaling::identity(n), &a, m).unwrap();
    assert_eq!(allocations_of_every_call(&map), 0);
    let scaled = ScaledMap::new(map);
    assert_eq!(allocations_of_every_call(&scaled), 0);
    // The counter does see allocations.
    let before = ALLOCATIONS.with(Cell::get);
    drop(std::hint::black_box(vec![0u8; 8]));
    assert_eq!(ALLOCATIONS.with(Cell::get) - before, 1);
}

/// The same at the paper's IV-A size (306 point strains, 7 hidden layers halving to r = 1, folded
/// onto 33 coefficients), from the first call on.
#[test]
fn paper_sized_decoder_does_not_allocate() {
    let (r, m) = (1, 33);
    let mut rng = SplitMix64::new(3);
    let decoder = Mlp::glorot(&[r, 38, 76, 153, 306], &mut rng).unwrap();
    let a: Vec<f64> = (0..m * 306).map(|_| rng.range(-1.0, 1.0)).collect();
    let map = DecoderMap::new(&decoder, &Scaling::identity(306), &a, m).unwrap();
    let (z, zd, g) = (vec![0.3], vec![1.0], vec![0.1; m]);
    let (mut c, mut c_z, mut c_z_dot) = (vec![0.0; m], vec![0.0; m * r], vec![0.0; m * r]);
    let (mut hess, mut scratch) = (vec![0.0; r * r], vec![0.0; map.scratch_len()]);
    let first = ALLOCATIONS.with(Cell::get);
    map.eval(&z, &mut c, &mut c_z, &mut scratch);
    map.eval_rate(&z, &zd, &mut c_z_dot, &mut scratch);
    map.add_weighted_hessian(&z, &g, &mut hess, &mut scratch);
    assert_eq!(ALLOCATIONS.with(Cell::get) - first, 0);
    let before = ALLOCATIONS.with(Cell::get);
    for _ in 0..3 {
        map.eval(&z, &mut c, &mut c_z, &mut scratch);
        map.eval_rate(&z, &zd, &mut c_z_dot, &mut scratch);
        map.add_weighted_hessian(&z, &g, &mut hess, &mut scratch);
    }
    assert_eq!(ALLOCATIONS.with(Cell::get) - before, 0);
    assert!(c.iter().chain(&c_z).chain(&hess).all(|v| v.is_finite()));
}
