//! The loader's errors: what is wrong with a glTF file, naming the accessor, buffer, mesh,
//! primitive, node, camera or light and the offending value. [`crate::Error::Gltf`] pairs
//! one with the file's path.

/// What is wrong with a glTF / GLB file (glTF 2.0 specification section in brackets).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GltfError {
    /// The file is larger than the loader reads.
    #[error("{bytes} bytes (at most {max})")]
    TooLarge {
        /// The file's size, bytes.
        bytes: u64,
        /// The largest size read, bytes.
        max: u64,
    },
    /// The `gltf` crate could not parse or validate the document.
    #[error("not a valid glTF 2.0 / GLB file: {reason}")]
    NotGltf {
        /// The parser's message.
        reason: String,
    },
    /// `asset.version` is not 2.x (§3.2).
    #[error("asset version `{version}`: expected a glTF 2.x file")]
    Version {
        /// The declared version.
        version: String,
    },
    /// A primitive's attribute names an accessor the file does not have.
    #[error(
        "meshes[{mesh}].primitives[{primitive}].attributes: accessor {accessor} does not exist (the file has {count})"
    )]
    MissingAccessor {
        /// Mesh index.
        mesh: usize,
        /// Primitive index within the mesh.
        primitive: usize,
        /// The accessor index named.
        accessor: usize,
        /// How many accessors the file has.
        count: usize,
    },
    /// `extensionsRequired` lists an extension nacre does not implement (§3.12).
    #[error(
        "the file requires the extension `{extension}`, which nacre does not implement (it implements {supported})"
    )]
    UnsupportedExtension {
        /// The extension.
        extension: String,
        /// The implemented extensions, comma-separated.
        supported: String,
    },
    /// A GLB buffer without the binary chunk.
    #[error("buffer {buffer}: the GLB binary chunk is missing")]
    MissingGlbChunk {
        /// Buffer index.
        buffer: usize,
    },
    /// A `data:` URI that is not base64.
    #[error("buffer {buffer}: only base64 `data:` URIs are supported")]
    DataUri {
        /// Buffer index.
        buffer: usize,
    },
    /// Malformed base64 in a `data:` URI.
    #[error("buffer {buffer}: its base64 data is malformed")]
    Base64 {
        /// Buffer index.
        buffer: usize,
    },
    /// A buffer file beside the glTF larger than the loader reads.
    #[error("buffer {buffer} (`{uri}`): {bytes} bytes (at most {max})")]
    BufferTooLarge {
        /// Buffer index.
        buffer: usize,
        /// The buffer's URI.
        uri: String,
        /// Its size, bytes.
        bytes: u64,
        /// The largest size read, bytes.
        max: u64,
    },
    /// A buffer shorter than its declared `byteLength`.
    #[error("buffer {buffer} holds {bytes} bytes, the file declares {declared} (truncated?)")]
    BufferShort {
        /// Buffer index.
        buffer: usize,
        /// Bytes present.
        bytes: usize,
        /// `byteLength`.
        declared: usize,
    },
    /// No primitive with anything to draw (triangles, lines or points) in the scene.
    #[error("the scene has nothing to draw (no triangles, lines or points)")]
    NoTriangles,
    /// A node tree deeper than the loader follows.
    #[error("node {node}: node hierarchy deeper than {max_depth} levels")]
    TooDeep {
        /// The node found too deep.
        node: usize,
        /// The deepest level followed.
        max_depth: usize,
    },
    /// A node whose world transform is not finite.
    #[error("node {node} has a non-finite transform")]
    NodeTransform {
        /// Node index.
        node: usize,
    },
    /// A `KHR_lights_punctual` light with values out of range.
    #[error("node {node}: light `{name}` (light {light}): {what}")]
    Light {
        /// The node placing it.
        node: usize,
        /// Light index.
        light: usize,
        /// Its name (or `light N`).
        name: String,
        /// The offending values and what was expected.
        what: String,
    },
    /// A camera with values out of range (§3.10).
    #[error("camera `{name}` (camera {camera}): {what}")]
    Camera {
        /// Camera index.
        camera: usize,
        /// Its name (or `camera N`).
        name: String,
        /// The offending values and what was expected.
        what: String,
    },
    /// A primitive without POSITION.
    #[error("mesh {mesh} primitive {primitive} has no POSITION")]
    NoPosition {
        /// Mesh index.
        mesh: usize,
        /// Primitive index.
        primitive: usize,
    },
    /// An attribute accessor of the wrong component type or dimensions.
    #[error("{semantic} accessor {accessor} is {found} (expected {expected})")]
    AccessorType {
        /// `POSITION`, `NORMAL`, …
        semantic: String,
        /// Accessor index.
        accessor: usize,
        /// Its component type and dimensions.
        found: String,
        /// What the attribute needs.
        expected: String,
    },
    /// An attribute whose count differs from POSITION's.
    #[error(
        "mesh {mesh} primitive {primitive}: {semantic} has {count} elements, POSITION {positions}"
    )]
    CountMismatch {
        /// Mesh index.
        mesh: usize,
        /// Primitive index.
        primitive: usize,
        /// The attribute.
        semantic: String,
        /// Its element count.
        count: usize,
        /// POSITION's count.
        positions: usize,
    },
    /// More vertices or triangle corners than the loader takes.
    #[error(
        "mesh {mesh} primitive {primitive}: {vertices} vertices and {corners} triangle corners so far (at most {max_vertices} and {max_corners})"
    )]
    TooManyVertices {
        /// Mesh index.
        mesh: usize,
        /// Primitive index.
        primitive: usize,
        /// Vertices over the scene so far.
        vertices: usize,
        /// Corners over the scene so far.
        corners: usize,
        /// The vertex limit.
        max_vertices: usize,
        /// The corner limit.
        max_corners: usize,
    },
    /// A triangle list whose corner count is not a multiple of 3.
    #[error("mesh {mesh} primitive {primitive}: {corners} triangle corners is not a multiple of 3")]
    NotTriangles {
        /// Mesh index.
        mesh: usize,
        /// Primitive index.
        primitive: usize,
        /// The corner count.
        corners: usize,
    },
    /// A LINES primitive whose end count is not a multiple of 2.
    #[error(
        "mesh {mesh} primitive {primitive}: {ends} line ends (mode LINES) is not a multiple of 2"
    )]
    NotLines {
        /// Mesh index.
        mesh: usize,
        /// Primitive index.
        primitive: usize,
        /// The end count.
        ends: usize,
    },
    /// A vertex position that is not finite (after the node transform).
    #[error(
        "mesh {mesh} primitive {primitive}: non-finite vertex position {value:?} (vertex {vertex})"
    )]
    NonFinitePosition {
        /// Mesh index.
        mesh: usize,
        /// Primitive index.
        primitive: usize,
        /// Vertex index.
        vertex: usize,
        /// The position.
        value: [f32; 3],
    },
    /// A vertex index beyond the vertices.
    #[error("mesh {mesh} primitive {primitive}: index {index} beyond {vertices} vertices")]
    IndexOutOfRange {
        /// Mesh index.
        mesh: usize,
        /// Primitive index.
        primitive: usize,
        /// The index.
        index: u32,
        /// The vertex count.
        vertices: usize,
    },
    /// A sparse index (§3.6.2.3) at or beyond the accessor's element count.
    #[error(
        "accessor {accessor}: sparse index {index} (entry {position}) beyond its {count} elements"
    )]
    SparseIndexOutOfRange {
        /// Accessor index.
        accessor: usize,
        /// The entry among the sparse indices.
        position: usize,
        /// The index.
        index: u32,
        /// The accessor's element count.
        count: usize,
    },
    /// Sparse indices that do not strictly increase (§3.6.2.3: "MUST strictly increase").
    #[error(
        "accessor {accessor}: sparse index {index} (entry {position}) after {previous}: the indices must strictly increase"
    )]
    SparseIndicesNotIncreasing {
        /// Accessor index.
        accessor: usize,
        /// The entry among the sparse indices.
        position: usize,
        /// The index before it.
        previous: u32,
        /// The index.
        index: u32,
    },
    /// A sparse accessor's indices or values running beyond their buffer view.
    #[error(
        "accessor {accessor}: sparse {part} need {needed} bytes of their buffer view's {view_bytes}"
    )]
    SparseBeyondView {
        /// Accessor index.
        accessor: usize,
        /// `indices` or `values`.
        part: String,
        /// Bytes they need (offset included).
        needed: u64,
        /// The view's length, bytes.
        view_bytes: u64,
    },
    /// A buffer view that ends beyond its buffer.
    #[error(
        "buffer view {view} ends at byte {end}, beyond its buffer's {buffer_bytes} bytes (truncated file?)"
    )]
    ViewBeyondBuffer {
        /// Buffer view index.
        view: usize,
        /// Its end, bytes.
        end: u64,
        /// The buffer's length, bytes.
        buffer_bytes: u64,
    },
    /// An accessor that runs beyond its buffer view.
    #[error("accessor {accessor} needs {needed} bytes of its buffer view's {view_bytes}")]
    AccessorBeyondView {
        /// Accessor index.
        accessor: usize,
        /// Bytes it needs.
        needed: u64,
        /// The view's length, bytes.
        view_bytes: u64,
    },
    /// A `KHR_draco_mesh_compression` primitive whose extension object, Draco stream or
    /// decoded attributes do not fit together (the extension's rules: `draco.rs`).
    #[error(
        "mesh {mesh} primitive {primitive}: KHR_draco_mesh_compression (buffer view {view}): {what}"
    )]
    Draco {
        /// Mesh index.
        mesh: usize,
        /// Primitive index.
        primitive: usize,
        /// The buffer view holding the Draco stream.
        view: usize,
        /// What is wrong, with the offending values (or the decoder's reason).
        what: String,
    },
    /// A malformed `KHR_draco_mesh_compression` object on a primitive.
    #[error("mesh {mesh} primitive {primitive}: KHR_draco_mesh_compression: {what}")]
    DracoExtension {
        /// Mesh index.
        mesh: usize,
        /// Primitive index.
        primitive: usize,
        /// The offending member and value.
        what: String,
    },
    /// A `KHR_texture_basisu` texture whose KTX2 picture cannot be used: a missing or bad
    /// image index, or a file that does not decode (`basisu.rs`).
    #[error("texture {texture} (KHR_texture_basisu, image {image}): {error}")]
    Basisu {
        /// Texture index.
        texture: usize,
        /// The image index the extension names.
        image: usize,
        /// What is wrong.
        error: Ktx2Error,
    },
}

/// What is wrong with the KTX 2.0 file of a `KHR_texture_basisu` texture (KTX 2.0 §3 and the
/// extension's "KTX2 image requirements").
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Ktx2Error {
    /// The image does not exist, or is not where its record says.
    #[error("{what}")]
    Image {
        /// What is wrong with the image record.
        what: String,
    },
    /// The bytes do not start with the KTX 2.0 identifier.
    #[error("not a KTX 2.0 file (its first 12 bytes are not the KTX2 identifier)")]
    NotKtx2,
    /// Fewer bytes than the header or the level index needs.
    #[error("{bytes} bytes, truncated (the KTX2 header and level index need {need})")]
    Truncated {
        /// The file's size, bytes.
        bytes: usize,
        /// Bytes the header and index need.
        need: usize,
    },
    /// `vkFormat` is not VK_FORMAT_UNDEFINED (a plain KTX2 texture, not Basis Universal).
    #[error(
        "vkFormat {vk_format}: KHR_texture_basisu wants 0 (VK_FORMAT_UNDEFINED, Basis Universal data)"
    )]
    VkFormat {
        /// The header's `vkFormat`.
        vk_format: u32,
    },
    /// Not a 2-D texture.
    #[error(
        "pixelDepth {depth}, layerCount {layers}, faceCount {faces}: KHR_texture_basisu wants a 2-D texture (0, 0 or 1, 1)"
    )]
    NotTwoD {
        /// The header's `pixelDepth`.
        depth: u32,
        /// The header's `layerCount`.
        layers: u32,
        /// The header's `faceCount`.
        faces: u32,
    },
    /// Zero or too large a width or height.
    #[error("{width}x{height} texels (at least 1, at most {max})")]
    Dimensions {
        /// The header's `pixelWidth`.
        width: u32,
        /// The header's `pixelHeight`.
        height: u32,
        /// The largest side read.
        max: u32,
    },
    /// A supercompression scheme the extension does not allow, or one that does not match
    /// the codec.
    #[error("supercompression scheme {scheme}{}: KHR_texture_basisu allows BasisLZ (1) for ETC1S, none (0) or Zstandard (2) for UASTC", codec.map_or(String::new(), |c| format!(" for {c} data")))]
    Supercompression {
        /// The header's `supercompressionScheme`.
        scheme: u32,
        /// The codec the data holds, when known.
        codec: Option<&'static str>,
    },
    /// More mip levels than any texture within the size limit has.
    #[error("levelCount {levels} (at most 32)")]
    LevelCount {
        /// The header's `levelCount`.
        levels: u32,
    },
    /// A level index entry pointing outside the file.
    #[error("level {level} lies at bytes {offset} + {length}, beyond the file's {bytes} bytes")]
    LevelOutside {
        /// The level.
        level: u32,
        /// Its `byteOffset`.
        offset: u64,
        /// Its `byteLength`.
        length: u64,
        /// The file's size, bytes.
        bytes: usize,
    },
    /// A Zstandard level whose uncompressed length is not that of its UASTC blocks.
    #[error(
        "level {level}: uncompressedByteLength {uncompressed}, expected {expected} (16 bytes per 4 × 4 UASTC block)"
    )]
    LevelSize {
        /// The level.
        level: u32,
        /// Its `uncompressedByteLength`.
        uncompressed: u64,
        /// 16 bytes per block of the level.
        expected: u64,
    },
    /// A Basis codec other than ETC1S and UASTC LDR (the extension's two).
    #[error("{codec} data (KHR_texture_basisu allows ETC1S and UASTC)")]
    Codec {
        /// The codec the transcoder found.
        codec: String,
    },
    /// The transcoder refused the data.
    #[error("the Basis Universal transcoder refused it ({reason})")]
    Transcoder {
        /// The transcoder's error.
        reason: String,
    },
    /// The transcoder failed (panicked) on damaged data.
    #[error("malformed Basis Universal data (the transcoder failed)")]
    Panicked,
}
