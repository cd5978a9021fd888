//! The bare-metal program: entry point, panic handler and the report.

use crate::measure::{milli_instructions_per_tick, paint_stack, sections, stack_used, Ticks};
use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hprintln};
use raytrail_embedded_example::raytrail_core::intersect::Watertight;
use raytrail_embedded_example::raytrail_core::wide::traverse::trace_wide_batch;
use raytrail_embedded_example::raytrail_core::wide::FastKernel;
use raytrail_embedded_example::{
    baked, grid_report, self_test, self_test_ray, FlashScene, Hit, NoObserver, Query, Ray, METHODS, SELF_TEST_RAYS,
};

/// What a build runs: everything (the default), or for footprint measurements only the measuring
/// scaffold, or the scaffold and one method (see build.rs).
#[allow(dead_code)]
enum Only {
    Everything,
    Nothing,
    Method(usize),
}

include!(concat!(env!("OUT_DIR"), "/only.rs"));

/// The method a one-method build traces (0 otherwise; unused then).
const ONLY_METHOD: usize = match ONLY {
    Only::Method(i) => i,
    _ => 0,
};

#[entry]
fn main() -> ! {
    hprintln!("raytrail-embedded-qemu: Cortex-M4F, sphereflake({}) baked into flash", baked::SPHEREFLAKE_DEPTH);
    let (text, rodata, data, bss) = sections();
    hprintln!("footprint text {} rodata {} data {} bss {} tables {}", text, rodata, data, bss, baked::TABLE_BYTES);
    // `ONLY` is a constant, so the branches not taken, and all they call, are not linked.
    match ONLY {
        Only::Everything => everything(),
        Only::Nothing => only("nothing", trace_nothing),
        Only::Method(_) => only(METHODS[ONLY_METHOD].name(), trace_grid::<ONLY_METHOD>),
    }
}

/// A footprint build: the scaffold and `grid` alone, one cost line, success.
fn only(name: &str, grid: fn(&FlashScene)) -> ! {
    let ticks = cortex_m::Peripherals::take().map(|p| Ticks::start(p.SYST));
    let (Some(t), Ok(scene)) = (&ticks, &FlashScene::load()) else {
        hprintln!("no SysTick, or the baked tables do not validate");
        exit(false);
    };
    let per_tick = milli_instructions_per_tick(t);
    let (milli, stack) = cost(t, scene, grid, per_tick);
    hprintln!("only {} insns/ray {}.{} stack {}", name, milli / 1000, milli % 1000 / 100, stack);
    exit(true)
}

/// The scaffold's grid: nothing traced.
#[inline(never)]
fn trace_nothing(scene: &FlashScene) {
    core::hint::black_box(scene);
}

/// The full program: the report, the costs of every method, the self-test.
fn everything() -> ! {
    // The digest first: every line here must equal the host's.
    let Some(report) = grid_report() else {
        hprintln!("the baked tables do not validate");
        exit(false);
    };
    for t in &report.tallies {
        hprintln!("{}", t);
    }
    hprintln!("grid digest {:016x}", report.digest);

    // Then the costs, traced again without an observer (as an application would).
    let ticks = cortex_m::Peripherals::take().map(|p| Ticks::start(p.SYST));
    let scene = FlashScene::load();
    if let (Some(t), Ok(scene)) = (&ticks, &scene) {
        let per_tick = milli_instructions_per_tick(t);
        hprintln!("calibration {}.{:03} instructions per SysTick tick", per_tick / 1000, per_tick % 1000);
        for (m, grid) in METHODS.iter().zip(GRIDS) {
            let (milli, stack) = cost(t, scene, grid, per_tick);
            hprintln!("cost {} insns/ray {}.{} stack {}", m.name(), milli / 1000, milli % 1000 / 100, stack);
        }
        let (milli, stack) = cost(t, scene, trace_grid_wide_batch, per_tick);
        hprintln!("cost bvh4-batch insns/ray {}.{} stack {}", milli / 1000, milli % 1000 / 100, stack);
    }
    let agreeing = self_test();
    hprintln!("self-test {}/{} rays agree across {} methods", agreeing, SELF_TEST_RAYS, METHODS.len());
    exit(agreeing == SELF_TEST_RAYS)
}

/// Ends the emulation with a status (qemu exits with 0 or 1); on a board without a debugger
/// attached, sleeps instead.
fn exit(ok: bool) -> ! {
    debug::exit(if ok { debug::EXIT_SUCCESS } else { debug::EXIT_FAILURE });
    loop {
        cortex_m::asm::wfi();
    }
}

/// Instructions per ray (times 1000; a ray is one closest-hit and one any-hit query) and the
/// peak stack in bytes of `grid`, one of [`GRIDS`].
#[inline(never)]
fn cost(t: &Ticks, scene: &FlashScene, grid: fn(&FlashScene), milli_per_tick: u64) -> (u64, usize) {
    let top = paint_stack();
    let start = t.now();
    grid(scene);
    let ticks = u64::from(t.since(start));
    (ticks * milli_per_tick / u64::from(SELF_TEST_RAYS), stack_used(top))
}

/// Traces the grid, closest hit and any hit, with `METHODS[M]`, one ray at a time as an
/// application would. The method is a constant, so this function holds only its code and its
/// state: its stack frame is the method's, and its symbol size (`trace_grid::<M>`) about its code.
#[inline(never)]
fn trace_grid<const M: usize>(scene: &FlashScene) {
    for i in 0..SELF_TEST_RAYS {
        let ray = self_test_ray(i);
        for q in [Query::Closest, Query::Any] {
            core::hint::black_box(scene.trace_method(&ray, METHODS[M], q, &mut NoObserver));
        }
    }
}

/// [`trace_grid`] for every method, in the order of [`METHODS`].
const GRIDS: [fn(&FlashScene); METHODS.len()] = [
    trace_grid::<0>,
    trace_grid::<1>,
    trace_grid::<2>,
    trace_grid::<3>,
    trace_grid::<4>,
    trace_grid::<5>,
    trace_grid::<6>,
    trace_grid::<7>,
    trace_grid::<8>,
    trace_grid::<9>,
    trace_grid::<10>,
    trace_grid::<11>,
    trace_grid::<12>,
    trace_grid::<13>,
];

/// The 4-wide BVH over the whole grid as one batch per query: the core's batch entry point sets
/// up the traversal stack once, where one call per ray sets it up every time.
#[inline(never)]
fn trace_grid_wide_batch(scene: &FlashScene) {
    let rays: [Ray; SELF_TEST_RAYS as usize] = core::array::from_fn(|i| self_test_ray(i as u32));
    let mut hits = [Hit::MISS; SELF_TEST_RAYS as usize];
    for q in [Query::Closest, Query::Any] {
        trace_wide_batch::<4, _, Watertight, FastKernel, _>(
            &scene.wide_memory(),
            scene.wide_root(),
            &rays,
            &mut hits,
            q,
            &mut NoObserver,
        );
        core::hint::black_box(&hits);
    }
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    hprintln!("panic: {}", info);
    exit(false)
}
