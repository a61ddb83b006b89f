//! Reading glTF vertex attributes as floats, whatever their component
//! type: 32-bit floats, or the normalised and plain integers that
//! KHR_mesh_quantization allows (the `gltf` crate's readers of positions,
//! normals and tangents read floats only). Accessors are bounds-checked
//! before any is read (`validate_accessors`), so reading cannot go out of range.

use gltf::accessor::DataType;

/// The elements of `accessor`, each as `N` floats: components the
/// accessor lacks are filled from `fill` (a colour without alpha reads as
/// opaque), components beyond `N` are dropped. Normalised integers map to
/// [0, 1] (unsigned) or [−1, 1] (signed), as glTF's section 3.11 says.
pub(crate) fn read_floats<const N: usize>(
    accessor: &gltf::Accessor<'_>,
    buffers: &[Vec<u8>],
    fill: [f32; N],
) -> Vec<[f32; N]> {
    let Some(view) = accessor.view() else { return Vec::new() };
    let Some(buffer) = buffers.get(view.buffer().index()) else { return Vec::new() };
    let components = accessor.dimensions().multiplicity();
    let data_type = accessor.data_type();
    let size = data_type.size();
    let stride = view.stride().unwrap_or(components * size);
    let start = view.offset() + accessor.offset();
    let normalized = accessor.normalized();
    let component = |at: usize| -> f32 {
        let Some(bytes) = buffer.get(at..at + size) else { return 0.0 };
        match data_type {
            DataType::F32 => f32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]),
            DataType::U8 if normalized => bytes[0] as f32 / 255.0,
            DataType::U8 => bytes[0] as f32,
            DataType::I8 if normalized => (bytes[0] as i8 as f32 / 127.0).max(-1.0),
            DataType::I8 => bytes[0] as i8 as f32,
            DataType::U16 if normalized => u16::from_le_bytes([bytes[0], bytes[1]]) as f32 / 65535.0,
            DataType::U16 => u16::from_le_bytes([bytes[0], bytes[1]]) as f32,
            DataType::I16 if normalized => (i16::from_le_bytes([bytes[0], bytes[1]]) as f32 / 32767.0).max(-1.0),
            DataType::I16 => i16::from_le_bytes([bytes[0], bytes[1]]) as f32,
            DataType::U32 => u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]) as f32,
        }
    };
    (0..accessor.count())
        .map(|i| {
            let element = start + i * stride;
            std::array::from_fn(|c| if c < components { component(element + c * size) } else { fill[c] })
        })
        .collect()
}
