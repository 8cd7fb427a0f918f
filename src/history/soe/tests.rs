use super::*;

/// Particles of the skipping test: several blocks, a partial last one.
const N: usize = 2 * LANES + 5;

/// D^{1/2} of every particle after each push of `v_p(t)` at the given steps.
fn run(mut h: SumOfExponentials, steps: &[f64]) -> Vec<f64> {
    let mut t = 0.0f64;
    let mut out = vec![];
    let mut past = vec![Vec3::zeros(); N];
    let v = |p: usize, t: f64| {
        let w = 1.0 + p as f64 * 0.37;
        Vec3::new((w * t).sin() + 0.3, (2.0 * w * t).cos(), 0.1 * p as f64)
    };
    for &dt in steps {
        let vs: Vec<Vec3> = (0..N).map(|p| v(p, t)).collect();
        h.push(&vs, dt);
        t += dt;
        h.prepare();
        h.past(&mut past);
        for (p, d) in past.iter().enumerate() {
            out.extend((h.current_weight() * v(p, t) + d).iter());
        }
    }
    out
}

#[test]
fn leaving_out_negligible_modes_changes_d_by_less_than_the_cut_off_promises() {
    let kernel = SoeKernel::build(1e-3, 1e-4, 3600.0).unwrap();
    let skipping = SumOfExponentials::new(kernel.clone(), N);
    // At 1/24 s four of the 16 modes are negligible; at 0.5 ms none.
    assert_eq!(skipping.active_modes(1.0 / 24.0), kernel.len() - 4);
    assert_eq!(skipping.active_modes(5e-4), kernel.len());
    let mut keeping = skipping.clone();
    // Every mode that can matter in f64 (factor e^{-s g} >= e^{-50}, about 2e-22).
    keeping.cut = SKIP_EXPONENT;
    // Fine steps, coarse ones (modes left out, their state goes stale), fine again (they
    // rejoin), coarse again.
    let steps: Vec<f64> = (0..760)
        .map(|k| {
            if (300..348).contains(&k) || k >= 700 {
                1.0 / 24.0
            } else {
                1e-4
            }
        })
        .collect();
    let (a, b) = (run(skipping, &steps), run(keeping, &steps));
    assert!(a.iter().chain(&b).all(|x| x.is_finite()));
    let scale = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let worst = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
    // The cut-off is 1/1000 of the kernel's own error (7.4e-4): 1e-6 of D at most.
    assert!(worst <= 1e-6 * scale, "{worst:e} of {scale:e}");
    assert!(worst > 0.0, "modes were left out, so something must differ");
}

#[test]
fn state_saved_while_modes_are_left_out_continues_bitwise() {
    let kernel = SoeKernel::build(1e-3, 1e-4, 3600.0).unwrap();
    let mut a = SumOfExponentials::new(kernel.clone(), N);
    let v = |k: usize| -> Vec<Vec3> {
        (0..N)
            .map(|p| Vec3::new((0.1 * k as f64 + p as f64).sin(), 0.2, p as f64 * 0.01))
            .collect()
    };
    // Coarse steps leave four modes out; save; then finer steps bring them back.
    let steps = |k: usize| if k < 30 { 1.0 / 24.0 } else { 1e-4 };
    for k in 0..30 {
        a.push(&v(k), steps(k));
    }
    let mut w = crate::bytes::ByteWriter::default();
    a.write_state(&mut w);
    let mut b = SumOfExponentials::new(kernel, N);
    b.read_state(&mut crate::bytes::ByteReader::new(&w.buf)).unwrap();
    let (mut pa, mut pb) = (vec![Vec3::zeros(); N], vec![Vec3::zeros(); N]);
    for k in 30..60 {
        a.push(&v(k), steps(k));
        b.push(&v(k), steps(k));
        a.prepare();
        b.prepare();
        a.past(&mut pa);
        b.past(&mut pb);
        assert_eq!(pa, pb, "step {k}");
    }
}

#[test]
fn the_pass_the_read_only_past_and_a_retry_give_the_same_bits() {
    let kernel = SoeKernel::build(1e-3, 1e-4, 3600.0).unwrap();
    let mut h = SumOfExponentials::new(kernel, N);
    let v = |k: usize| -> Vec<Vec3> {
        (0..N)
            .map(|p| Vec3::new((0.3 * k as f64 + p as f64).sin(), 0.1 * p as f64, -0.2))
            .collect()
    };
    let pass = soe_pass;
    // Steps of two sizes, so that modes are left out and restart.
    let step = |k: usize| if k % 7 < 3 { 1.0 / 24.0 } else { 1e-3 };
    // Nothing recorded yet: no past at all.
    assert!(pass(&mut h).iter().all(|p| *p == Vec3::zeros()));
    for k in 0..20 {
        let mut rec = v(k);
        h.record(&mut rec, step(k));
        // Before the fold: the read-only past folds copies, over any range.
        h.prepare();
        let mut before = vec![Vec3::zeros(); N];
        h.past(&mut before);
        let mut part = vec![Vec3::zeros(); 7];
        h.past_range(LANES + 5, &mut part);
        assert_eq!(part[..], before[LANES + 5..LANES + 12], "step {k}");
        // The pass folds in place and gives the same bits.
        let folded = pass(&mut h);
        assert_eq!(folded, before, "step {k}");
        // A second pass without a new record (a retry after a failed step) sums the
        // folded modes: the same bits again, and the read-only past agrees.
        assert_eq!(pass(&mut h), folded, "step {k}");
        let mut after = vec![Vec3::zeros(); N];
        h.past(&mut after);
        assert_eq!(after, folded, "step {k}");
        if k == 0 {
            // The first sample alone: only its panel's weight, no sum over the modes.
            let expected: Vec<Vec3> = v(0).iter().map(|x| h.w_prev * x + Vec3::zeros()).collect();
            assert_eq!(folded, expected);
        } else {
            assert!(folded.iter().all(|p| p.norm() > 1e-6), "step {k}");
        }
    }
}

#[test]
fn phi_series_and_closed_form_agree_at_the_switch() {
    let (o1, n1) = phi(0.05 - 1e-12);
    let z: f64 = 0.05;
    let e = (-z).exp();
    approx::assert_relative_eq!(o1, (1.0 - e * (1.0 + z)) / (z * z), max_relative = 1e-9);
    approx::assert_relative_eq!(n1, (z - 1.0 + e) / (z * z), max_relative = 1e-9);
    assert_eq!(phi(0.0), (0.5, 0.5));
}

/// A step's pass over every particle, in tiles of one block (the last one partial) as a
/// step hands them out.
fn soe_pass(h: &mut SumOfExponentials) -> Vec<Vec3> {
    let mut out = vec![Vec3::zeros(); N];
    let p = h.begin();
    for (b, o) in out.chunks_mut(LANES).enumerate() {
        // SAFETY: disjoint blocks, each once.
        unsafe { p.past_range(b * LANES, o) };
    }
    h.end();
    out
}

/// [`soe_pass`] of a history holding SOE.
fn step_pass(h: &mut crate::history::History) -> Vec<Vec3> {
    match h {
        crate::history::History::SumOfExponentials(s) => soe_pass(s),
        _ => unreachable!("an SOE history"),
    }
}

fn deferred(kernel: &SoeKernel) -> crate::history::History {
    crate::history::History::SumOfExponentials(Box::new(
        SumOfExponentials::new(kernel.clone(), N).with_deferred_fold(true),
    ))
}

fn soe(h: &crate::history::History) -> &SumOfExponentials {
    match h {
        crate::history::History::SumOfExponentials(s) => s,
        _ => unreachable!("an SOE history"),
    }
}

fn sample(k: usize) -> Vec<Vec3> {
    (0..N)
        .map(|p| {
            Vec3::new(
                (0.3 * k as f64 + p as f64).sin(),
                0.1 * p as f64 - 0.5,
                (0.7 * k as f64).cos(),
            )
        })
        .collect()
}

/// Steps of one size with a run of coarser ones (four modes left out, then restarting)
/// and a change back; step 37 is refused once (its pass runs twice).
fn deferred_step(k: usize) -> f64 {
    match k {
        20..=22 => 1.0 / 24.0,
        41..=45 => 2e-3,
        _ => 1e-3,
    }
}

#[test]
fn deferring_keeps_the_modes_bits_and_the_sums_within_rounding() {
    let kernel = SoeKernel::build(1e-3, 1e-4, 3600.0).unwrap();
    let mut every =
        crate::history::History::SumOfExponentials(Box::new(SumOfExponentials::new(kernel.clone(), N)));
    let mut other = deferred(&kernel);
    assert!(soe(&other).defers_folds() && !soe(&every).defers_folds());
    let (mut light, mut worst, mut scale) = (0, 0.0f64, 0.0f64);
    for k in 0..70 {
        for _ in 0..if k == 37 { 2 } else { 1 } {
            let was_pending = soe(&other).clock.recorded.is_some();
            let folded_before = soe(&other).clock.recorded.is_none();
            let (a, b) = (step_pass(&mut every), step_pass(&mut other));
            let s = soe(&other);
            if was_pending && s.clock.recorded.is_some() {
                light += 1;
            }
            if s.clock.recorded.is_none() && !folded_before || k == 0 {
                // The deferred history folded everything that waited: the same modes.
                let (x, y) = (&soe(&every).modes[..], &s.modes[..]);
                assert!(
                    x.iter().zip(y).all(|(x, y)| x.to_bits() == y.to_bits()),
                    "step {k}"
                );
            }
            for (a, b) in a.iter().zip(&b) {
                worst = worst.max((a - b).amax());
                scale = scale.max(a.amax());
            }
        }
        every.record(&mut sample(k), deferred_step(k));
        other.record(&mut sample(k), deferred_step(k));
    }
    // Every other step of one size left its fold for later (70 steps, 9 of other sizes
    // or after a change, one retry).
    assert!(light >= 30, "{light} passes left their fold for later");
    assert!(scale > 1e-3);
    assert!(worst <= 1e-13 * scale, "{worst:e} of {scale:e}");
    // After a flush both hold the same modes and give the same sum.
    let (mut a, mut b) = (every.clone(), other.clone());
    if let (crate::history::History::SumOfExponentials(a), crate::history::History::SumOfExponentials(b)) =
        (&mut a, &mut b)
    {
        a.flush();
        b.flush();
        assert!(a
            .modes
            .iter()
            .zip(b.modes.iter())
            .all(|(x, y)| x.to_bits() == y.to_bits()));
    }
    assert_eq!(step_pass(&mut a), step_pass(&mut b));
}

/// `ahead` summed again from the modes (as after a snapshot is read) on the pool, for a
/// cloth of several chunks, holds the bits the folding pass left in it.
#[test]
fn ahead_summed_again_on_the_pool_has_the_passs_bits() {
    let kernel = SoeKernel::build(1e-3, 1e-4, 3600.0).unwrap();
    let n = crate::parallel::min_parallel().max(3 * crate::parallel::CHUNK) + 21;
    let mut h = SumOfExponentials::new(kernel, n).with_deferred_fold(true);
    let v = |k: usize| -> Vec<Vec3> {
        (0..n)
            .map(|p| {
                Vec3::new(
                    (0.3 * k as f64 + p as f64).sin(),
                    1e-4 * p as f64,
                    (0.7 * k as f64).cos(),
                )
            })
            .collect()
    };
    let mut checked = 0;
    for k in 0..6 {
        let mut out = vec![Vec3::zeros(); n];
        let p = h.begin();
        for (b, o) in out.chunks_mut(LANES).enumerate() {
            // SAFETY: disjoint blocks, each once.
            unsafe { p.past_range(b * LANES, o) };
        }
        h.end();
        if h.clock.pending.is_none() && h.clock.has_prev && h.clock.recorded.is_none() {
            let want = h.ahead.clone();
            h.ahead.fill(Vec3::zeros());
            h.recompute_ahead();
            let bits = |a: &[Vec3]| {
                a.iter()
                    .flat_map(|p| p.iter().map(|c| c.to_bits()))
                    .collect::<Vec<_>>()
            };
            assert_eq!(bits(&h.ahead), bits(&want), "after {k} steps");
            assert!(want.iter().any(|s| s.x != 0.0));
            checked += 1;
        }
        h.record(&mut v(k), 1e-3);
    }
    assert!(checked > 0);
}

#[test]
fn a_deferred_state_written_and_read_continues_bitwise_and_its_bytes_are_canonical() {
    let kernel = SoeKernel::build(1e-3, 1e-4, 3600.0).unwrap();
    let bytes = |h: &crate::history::History| {
        let mut w = crate::bytes::ByteWriter::default();
        h.write_state(&mut w).unwrap();
        w.buf
    };
    // Saved after every record: nothing pending and the next pass light, a sample
    // pending, a size change, the coarse steps.
    let mut phases = std::collections::BTreeSet::new();
    for save in 1..50 {
        let mut a = deferred(&kernel);
        for k in 0..save {
            step_pass(&mut a);
            a.record(&mut sample(k), deferred_step(k));
        }
        let s = soe(&a);
        phases.insert((s.clock.pending.is_some(), s.light_eligible()));
        let written = bytes(&a);
        // A refused step's pass leaves a state with the same bytes.
        let mut refused = a.clone();
        step_pass(&mut refused);
        assert_eq!(bytes(&refused), written, "saved after {save} steps");
        let mut b = deferred(&kernel);
        b.read_state(&mut crate::bytes::ByteReader::new(&written))
            .unwrap();
        for k in save..save + 25 {
            assert_eq!(
                step_pass(&mut a),
                step_pass(&mut b),
                "saved after {save}, step {k}"
            );
            a.record(&mut sample(k), deferred_step(k));
            b.record(&mut sample(k), deferred_step(k));
        }
    }
    // Every phase was saved: pending, light next, neither.
    assert_eq!(phases.len(), 3, "{phases:?}");
}
