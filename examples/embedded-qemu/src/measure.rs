//! What the device measures about itself: instructions (SysTick under qemu's `-icount`), peak
//! stack (a painted stack), and its own flash and RAM footprint (the linker's section symbols).
//!
//! qemu models no cycle counter (DWT CYCCNT reads zero), but with `-icount shift=0` its virtual
//! clock advances exactly 1 ns per executed instruction, and SysTick, clocked from the
//! processor clock, counts that virtual time. A calibration loop of known length converts ticks
//! to instructions, so the figures need no knowledge of the board's clock.

use core::arch::asm;
use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::SYST;

/// SysTick's counter is 24 bits wide and counts down.
const SYSTICK_MASK: u32 = 0x00ff_ffff;

/// A free-running SysTick (reload at its maximum, no interrupt).
pub struct Ticks(SYST);

impl Ticks {
    /// Starts SysTick from the processor clock.
    pub fn start(mut syst: SYST) -> Ticks {
        syst.disable_interrupt();
        syst.set_clock_source(SystClkSource::Core);
        syst.set_reload(SYSTICK_MASK);
        syst.clear_current();
        syst.enable_counter();
        Ticks(syst)
    }

    /// The counter now.
    #[inline(always)]
    pub fn now(&self) -> u32 {
        SYST::get_current()
    }

    /// Ticks from `start` to now; right while less than 2^24 ticks passed (the callers time
    /// one method at a time, far below that).
    #[inline(always)]
    pub fn since(&self, start: u32) -> u32 {
        start.wrapping_sub(self.now()) & SYSTICK_MASK
    }
}

/// Iterations of the calibration loop (two instructions each).
const CALIBRATION_LOOPS: u32 = 1_000_000;

/// Instructions per SysTick tick, times 1000: the ticks a loop of `2 * CALIBRATION_LOOPS`
/// instructions (`subs`, `bne`) takes. Under `-icount shift=0` on the mps2-an386 (25 MHz) this
/// is 40000; without `-icount` it follows the host's speed and means nothing.
pub fn milli_instructions_per_tick(t: &Ticks) -> u64 {
    let start = t.now();
    // SAFETY: a counted loop on one scratch register; no memory, no stack.
    unsafe {
        asm!(
            "2:",
            "subs {n}, {n}, #1",
            "bne 2b",
            n = inout(reg) CALIBRATION_LOOPS => _,
            options(nomem, nostack),
        );
    }
    let ticks = u64::from(t.since(start).max(1));
    2 * u64::from(CALIBRATION_LOOPS) * 1000 / ticks
}

/// The value painted over unused stack.
const PAINT: u32 = 0xdead_beef;
/// Bytes of stack painted below the caller's frame: more than any method needs (the 4-wide
/// traversal's 448-entry stack is the largest, about 7 KiB).
const PAINT_BYTES: usize = 32 * 1024;

extern "C" {
    static mut __ebss: u32;
}

/// Paints the stack below the current stack pointer and returns the painted range's top; pair
/// with [`stack_used`] after the code to measure.
#[inline(never)]
pub fn paint_stack() -> usize {
    let sp = cortex_m::register::msp::read() as usize;
    // Leave this function's own frame (and a margin) untouched.
    let top = sp - 256;
    let floor = core::ptr::addr_of!(__ebss) as usize;
    let bottom = top.saturating_sub(PAINT_BYTES).max(floor);
    let mut p = bottom;
    while p < top {
        // SAFETY: [bottom, top) lies between the end of .bss and the live stack: unused RAM
        // that nothing else writes (no interrupts are enabled).
        unsafe { core::ptr::write_volatile(p as *mut u32, PAINT) };
        p += 4;
    }
    top
}

/// Bytes below `top` that were written since [`paint_stack`]: the deepest the stack grew.
#[inline(never)]
pub fn stack_used(top: usize) -> usize {
    let floor = core::ptr::addr_of!(__ebss) as usize;
    let bottom = top.saturating_sub(PAINT_BYTES).max(floor);
    let mut p = bottom;
    // SAFETY: reads of the painted range.
    while p < top && unsafe { core::ptr::read_volatile(p as *const u32) } == PAINT {
        p += 4;
    }
    top - p
}

extern "C" {
    static __etext: u32;
    static __srodata: u32;
    static __erodata: u32;
    static __sdata: u32;
    static __edata: u32;
    static __sbss: u32;
}

/// Section sizes from the linker's symbols: (code, read-only data, initialized data, zeroed
/// data) in bytes. Flash holds the first three (code from address 0, vector table included),
/// RAM the last two.
pub fn sections() -> (usize, usize, usize, usize) {
    // Taking a linker symbol's address reads nothing.
    let a = |s: *const u32| s as usize;
    (
        a(core::ptr::addr_of!(__etext)),
        a(core::ptr::addr_of!(__erodata)) - a(core::ptr::addr_of!(__srodata)),
        a(core::ptr::addr_of!(__edata)) - a(core::ptr::addr_of!(__sdata)),
        a(core::ptr::addr_of!(__ebss)) - a(core::ptr::addr_of!(__sbss)),
    )
}
