//! The loader's size limits, shared by the document, primitive and texture readers.

/// Largest glTF/GLB file read, bytes (and largest external buffer).
pub const MAX_FILE_BYTES: u64 = 256 << 20;

/// Largest number of vertices over all primitives.
pub const MAX_VERTICES: usize = 4_000_000;

/// Largest number of triangle corners (indices) over all primitives.
pub const MAX_INDICES: usize = 12_000_000;

/// Largest width or height of a texture (pictures, KTX2 files, thickness textures), texels.
pub const MAX_TEXTURE_DIMENSION: u32 = 8192;
