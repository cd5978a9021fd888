//! Whether the adapter's driver can keep 32-bit subnormals when a kernel asks it to
//! (`VkPhysicalDeviceFloatControlsProperties::shaderDenormPreserveFloat32`).
//!
//! wgpu does not report float controls, so the property is read through wgpu's Vulkan adapter with
//! `ash` (wgpu's own Vulkan binding, the same version). Other APIs report `false`: their kernels
//! stay WGSL, and the numerics probe says whether that adapter flushes.

/// Whether the driver of `adapter` reports that kernels compiled with `DenormPreserve` (see
/// [`crate::spirv`]) keep 32-bit subnormals; `None` where it cannot be asked (not Vulkan).
#[cfg(any(windows, all(unix, not(target_vendor = "apple"), not(target_family = "wasm"))))]
pub(crate) fn driver_can_preserve_subnormals(adapter: &wgpu::Adapter) -> Option<bool> {
    use ash::vk;
    // SAFETY: the raw handles are only used for a properties query while `adapter` is alive.
    let hal = unsafe { adapter.as_hal::<wgpu::hal::api::Vulkan>() }?;
    let instance = hal.shared_instance().raw_instance();
    let mut float_controls = vk::PhysicalDeviceFloatControlsProperties::default();
    let mut properties = vk::PhysicalDeviceProperties2::default().push_next(&mut float_controls);
    // SAFETY: a valid physical device of this instance; Vulkan 1.1 (properties2) is what wgpu
    // requires of a Vulkan adapter it offers with SHADER_F64 and passthrough.
    unsafe { instance.get_physical_device_properties2(hal.raw_physical_device(), &mut properties) };
    Some(float_controls.shader_denorm_preserve_float32 == vk::TRUE)
}

#[cfg(not(any(windows, all(unix, not(target_vendor = "apple"), not(target_family = "wasm")))))]
pub(crate) fn driver_can_preserve_subnormals(_adapter: &wgpu::Adapter) -> Option<bool> {
    None
}
