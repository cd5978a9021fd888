//! What the adapter's shader compiler does to floating-point arithmetic, measured: whether it
//! contracts `a * b + c` into a fused multiply-add, how accurate its division is, whether it
//! flushes subnormals, and whether the kernels' own correctly rounded division (`div_rn`)
//! matches the CPU bit for bit. NUMERICS.md explains what the kernels do about each.

use crate::device::{device_error, Gpu};
use crate::pipelines::buffer_layout;
use raytrail_core::Error;
use wgpu::util::DeviceExt;

/// The probe's findings over its samples.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct NumericsProbe {
    /// Samples tested.
    pub samples: usize,
    /// Samples where the kernels' `div_rn` differs from the CPU's division (must be 0).
    pub div_rn_mismatches: usize,
    /// Samples where the native WGSL `/` differs from the CPU's correctly rounded division.
    pub native_division_mismatches: usize,
    /// Samples where the native `a * b + c` came out fused (rounded once).
    pub contracted: usize,
    /// Samples where `opq(a * b) + c` differs from the CPU's unfused result (must be 0).
    pub fenced_mismatches: usize,
    /// Samples with a subnormal operand or product whose fenced result differs from the CPU's
    /// (the adapter flushes subnormals; these are also counted in `fenced_mismatches`).
    pub subnormal_mismatches: usize,
}

impl NumericsProbe {
    /// Whether the kernels' own arithmetic matched the CPU everywhere.
    pub fn kernels_exact(&self) -> bool {
        self.div_rn_mismatches == 0 && self.fenced_mismatches == 0
    }

    /// One line for reports.
    pub fn summary(&self) -> String {
        format!(
            "{} samples: div_rn {} mismatches, fenced products {} mismatches; native: division off in {}, \
             contraction in {}, subnormal products changed in {}",
            self.samples,
            self.div_rn_mismatches,
            self.fenced_mismatches,
            self.native_division_mismatches,
            self.contracted,
            self.subnormal_mismatches
        )
    }
}

/// Deterministic samples: random bit patterns of every magnitude, then the special cases.
fn samples(n: usize) -> Vec<[u32; 4]> {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let special = [0u32, 0x8000_0000, 1, 0x8000_0001, 0x007f_ffff, 0x0080_0000, 0x3f80_0000, 0x7f7f_ffff, 0x7f80_0000];
    let mut out = Vec::with_capacity(n + special.len() * special.len());
    for &a in &special {
        for &b in &special {
            out.push([a, b, 0, 0]);
        }
    }
    while out.len() < n {
        let r = next();
        let (a, b) = (r as u32, (r >> 32) as u32);
        // A third of the samples in a narrow exponent band, where products and sums cancel.
        let c = match out.len() % 3 {
            0 => (-(f32::from_bits(a) * f32::from_bits(b))).to_bits(),
            1 => (next() as u32 & 0x807f_ffff) | 0x3f00_0000,
            _ => next() as u32,
        };
        out.push([a, b, c, 0]);
    }
    out
}

/// Runs the probe on `gpu`.
pub(crate) fn probe(gpu: &Gpu, n: usize) -> Result<NumericsProbe, Error> {
    let source = format!("{}\n{}", raytrail_shaders::PROBE.text, raytrail_shaders::NUMERICS.text);
    let input = samples(n);
    let d = &gpu.device;
    let out: Vec<[u32; 4]> = gpu.checked("running the numerics probe", || -> Result<Vec<[u32; 4]>, Error> {
        // shaders/probe.wgsl: a uniform, the samples (read), the results (write).
        let (bind_layout, layout) = buffer_layout(gpu, "numerics probe", &[None, Some(true), Some(false)]);
        // Compiled as the kernels are, so it measures what they get.
        let pipeline = gpu.compute_pipeline("numerics probe", &source, &[], &layout)?;
        let bytes = (input.len() * 16) as u64;
        let zero = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("zero"),
            contents: bytemuck::bytes_of(&[0u32; 4]),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let src = d.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("samples"),
            contents: bytemuck::cast_slice(&input),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let dst = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("results"),
            size: bytes,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let back = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some("results read-back"),
            size: bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bind = d.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("numerics probe"),
            layout: &bind_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: zero.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: src.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: dst.as_entire_binding() },
            ],
        });
        let mut enc = d.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &bind, &[]);
            pass.dispatch_workgroups(input.len().div_ceil(64) as u32, 1, 1);
        }
        enc.copy_buffer_to_buffer(&dst, 0, &back, 0, bytes);
        gpu.queue.submit([enc.finish()]);
        crate::batch::read::<[u32; 4]>(gpu, &back, input.len())
    })??;
    if out.len() != input.len() {
        return Err(device_error("the numerics probe returned too few results"));
    }
    let mut p = NumericsProbe { samples: input.len(), ..NumericsProbe::default() };
    let same = |x: f32, bits: u32| x.to_bits() == bits || (x.is_nan() && f32::from_bits(bits).is_nan());
    for (s, r) in input.iter().zip(&out) {
        let (a, b, c) = (f32::from_bits(s[0]), f32::from_bits(s[1]), f32::from_bits(s[2]));
        let q = a / b;
        p.div_rn_mismatches += usize::from(!same(q, r[0]));
        p.native_division_mismatches += usize::from(!same(q, r[1]));
        let unfused = a * b + c;
        let fused = a.mul_add(b, c);
        p.contracted += usize::from(!same(unfused, r[2]) && same(fused, r[2]));
        p.fenced_mismatches += usize::from(!same(unfused, r[3]));
        let subnormal = [a, b, c, a * b].iter().any(|x| x.is_subnormal());
        p.subnormal_mismatches += usize::from(subnormal && !same(unfused, r[3]));
    }
    Ok(p)
}
