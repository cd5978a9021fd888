//! Kernels as SPIR-V that asks the driver to keep subnormals (`SPV_KHR_float_controls`'
//! `DenormPreserve` execution mode).
//!
//! Some Vulkan drivers (NVIDIA's) flush 32-bit subnormal operands and results to zero unless the
//! module asks otherwise; the CPU keeps them, so a ray whose slab products are subnormal (a
//! direction component near `f32::MAX`) took different decisions on the two. WGSL cannot say how
//! subnormals are handled and naga emits no float-controls modes, so on adapters that can preserve
//! them the kernel is compiled here with naga (overrides resolved, the bounds-check policy wgpu
//! uses for indices) and the mode is added to the module, which wgpu then hands to the driver
//! unchanged (its shader passthrough).

use naga::back::spv;
use naga::proc::{BoundsCheckPolicies, BoundsCheckPolicy};

/// SPIR-V version written: 1.3 runs on every Vulkan 1.1 device; float controls are an extension
/// there (core from 1.4), so the module declares it.
const LANG_VERSION: (u8, u8) = (1, 3);
/// `OpExtension`.
const OP_EXTENSION: u16 = 10;
/// `OpEntryPoint`.
const OP_ENTRY_POINT: u16 = 15;
/// `OpExecutionMode`.
const OP_EXECUTION_MODE: u16 = 16;
/// `OpCapability`.
const OP_CAPABILITY: u16 = 17;
/// Capability `DenormPreserve` (`SPV_KHR_float_controls`).
const CAPABILITY_DENORM_PRESERVE: u32 = 4464;
/// Execution mode `DenormPreserve`; its operand is the floating-point width it applies to.
const MODE_DENORM_PRESERVE: u32 = 4459;
/// The extension's name, as `OpExtension` spells it.
const EXTENSION: &str = "SPV_KHR_float_controls";
/// Words of the module header before the first instruction.
const HEADER_WORDS: usize = 5;

/// Compiles the WGSL `source` (entry point `main`, compute) to SPIR-V with `overrides` applied and
/// 32-bit subnormals preserved. Errors name the stage that failed.
pub(crate) fn compile_preserving_subnormals(source: &str, overrides: &[(&str, f64)]) -> Result<Vec<u32>, String> {
    add_denorm_preserve(&write_spirv(source, overrides)?)
}

/// Compiles the WGSL `source` to SPIR-V as it is, with `overrides` applied.
fn write_spirv(source: &str, overrides: &[(&str, f64)]) -> Result<Vec<u32>, String> {
    let module = naga::front::wgsl::parse_str(source).map_err(|e| e.emit_to_string(source))?;
    let info = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::FLOAT64)
        .validate(&module)
        .map_err(|e| format!("validation: {}", e.emit_to_string(source)))?;
    let mut constants = naga::back::PipelineConstants::default();
    for &(name, value) in overrides {
        constants.insert(name.to_string(), value);
    }
    let stage = naga::ShaderStage::Compute;
    let (module, info) =
        naga::back::pipeline_constants::process_overrides(&module, &info, Some((stage, "main")), &constants)
            .map_err(|e| format!("overrides: {e}"))?;
    let options = spv::Options {
        lang_version: LANG_VERSION,
        // Indices clamped as wgpu clamps them. Buffer accesses are left to the device's robust
        // buffer access (core Vulkan, which wgpu enables), as wgpu leaves them on devices with
        // robustBufferAccess2.
        bounds_check_policies: BoundsCheckPolicies {
            index: BoundsCheckPolicy::Restrict,
            buffer: BoundsCheckPolicy::Unchecked,
            image_load: BoundsCheckPolicy::Restrict,
            binding_array: BoundsCheckPolicy::Unchecked,
        },
        ..spv::Options::default()
    };
    let pipeline = spv::PipelineOptions { shader_stage: stage, entry_point: "main".into() };
    spv::write_vec(&module, &info, &options, Some(&pipeline)).map_err(|e| format!("SPIR-V: {e}"))
}

/// One instruction's opcode and word count.
fn split(word: u32) -> (u16, usize) {
    ((word & 0xffff) as u16, (word >> 16) as usize)
}

/// The `OpExtension` instruction naming [`EXTENSION`] (a nul-terminated string padded to words).
fn extension_instruction() -> Vec<u32> {
    let mut bytes = EXTENSION.as_bytes().to_vec();
    bytes.push(0);
    bytes.resize(bytes.len().div_ceil(4) * 4, 0);
    let mut out = vec![0];
    out.extend(bytes.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])));
    out[0] = ((out.len() as u32) << 16) | u32::from(OP_EXTENSION);
    out
}

/// `words` with the `DenormPreserve` capability, the extension and, for every entry point, the
/// execution mode for 32-bit floats, each in the section the SPIR-V layout rules put it.
pub(crate) fn add_denorm_preserve(words: &[u32]) -> Result<Vec<u32>, String> {
    if words.len() < HEADER_WORDS || words[0] != 0x0723_0203 {
        return Err("not a SPIR-V module".into());
    }
    let mut out = words[..HEADER_WORDS].to_vec();
    let mut at = HEADER_WORDS;
    let (mut declared, mut entry_points, mut modes_added) = (false, Vec::new(), false);
    while at < words.len() {
        let (op, count) = split(words[at]);
        if count == 0 || at + count > words.len() {
            return Err(format!("malformed instruction at word {at}"));
        }
        // Capabilities come first, then extensions: ours go right after the last capability.
        if !declared && op != OP_CAPABILITY {
            out.extend([(2 << 16) | u32::from(OP_CAPABILITY), CAPABILITY_DENORM_PRESERVE]);
            out.extend(extension_instruction());
            declared = true;
        }
        // Execution modes follow the entry points: ours go right after the last entry point.
        if !entry_points.is_empty() && !modes_added && op != OP_ENTRY_POINT {
            for &id in &entry_points {
                out.extend([(4 << 16) | u32::from(OP_EXECUTION_MODE), id, MODE_DENORM_PRESERVE, 32]);
            }
            modes_added = true;
        }
        if op == OP_ENTRY_POINT {
            entry_points.push(words[at + 2]);
        }
        out.extend_from_slice(&words[at..at + count]);
        at += count;
    }
    if !modes_added {
        return Err("the module has no entry point".into());
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn instructions(words: &[u32]) -> Vec<&[u32]> {
        let mut out = Vec::new();
        let mut at = HEADER_WORDS;
        while at < words.len() {
            let (_, count) = split(words[at]);
            out.push(&words[at..at + count]);
            at += count;
        }
        out
    }

    #[test]
    fn the_probe_kernel_gets_capability_extension_and_mode_in_their_sections() {
        let source = format!("{}\n{}", raytrail_shaders::PROBE.text, raytrail_shaders::NUMERICS.text);
        let words = compile_preserving_subnormals(&source, &[]).expect("compiles");
        let ops: Vec<u16> = instructions(&words).iter().map(|i| split(i[0]).0).collect();
        let caps = ops.iter().take_while(|&&op| op == OP_CAPABILITY).count();
        let ins = instructions(&words);
        assert!(ins[..caps].iter().any(|i| i[1] == CAPABILITY_DENORM_PRESERVE), "capability declared");
        assert_eq!(ops[caps], OP_EXTENSION, "the extension follows the capabilities");
        let name: Vec<u8> = ins[caps][1..].iter().flat_map(|w| w.to_le_bytes()).take_while(|&b| b != 0).collect();
        assert_eq!(name, EXTENSION.as_bytes());
        let last_entry = ops.iter().rposition(|&op| op == OP_ENTRY_POINT).expect("an entry point");
        let entry_id = ins[last_entry][2];
        assert_eq!(ins[last_entry + 1], &[(4 << 16) | 16, entry_id, MODE_DENORM_PRESERVE, 32]);
        // Without the three additions, it is the module naga wrote, word for word.
        let added = |i: &&[u32]| {
            i[..] == [(2 << 16) | 17, CAPABILITY_DENORM_PRESERVE]
                || i[..] == extension_instruction()[..]
                || i[..] == [(4 << 16) | 16, entry_id, MODE_DENORM_PRESERVE, 32]
        };
        let kept: Vec<u32> = ins.iter().filter(|i| !added(i)).flat_map(|i| i.iter().copied()).collect();
        let plain = write_spirv(&source, &[]).expect("compiles");
        assert_eq!(kept[..], plain[HEADER_WORDS..]);
        assert_eq!(words[..HEADER_WORDS], plain[..HEADER_WORDS]);
    }

    #[test]
    fn overrides_are_resolved_before_the_module_is_written() {
        let source = "override K: u32 = 1u;\n@group(0) @binding(0) var<storage, read_write> o: array<u32>;\n\
                      @compute @workgroup_size(1) fn main() { o[0] = K; }";
        let a = compile_preserving_subnormals(source, &[("K", 7.0)]).expect("compiles");
        let b = compile_preserving_subnormals(source, &[("K", 9.0)]).expect("compiles");
        assert_ne!(a, b, "the override's value is in the module");
        assert!(compile_preserving_subnormals(source, &[("NOPE", 1.0)]).is_err(), "an unknown override is an error");
    }

    #[test]
    fn non_spirv_input_is_an_error_not_a_panic() {
        assert!(add_denorm_preserve(&[]).is_err());
        assert!(add_denorm_preserve(&[1, 2, 3, 4, 5]).is_err());
        assert!(add_denorm_preserve(&[0x0723_0203, 0, 0, 1, 0, 0xffff_0011]).is_err(), "truncated instruction");
    }
}
