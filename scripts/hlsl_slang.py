"""Compiles the engine HLSL with Slang (PyPI's slangpy): shaders/hlsl/nacre.hlsl inside a
compute probe calling each technique (film-lut, fourier, rough-film-lut), and
shaders/hlsl/unity/NacreShaderGraph.hlsl with stand-ins of Shader Graph's UnityTexture3D /
UnityTexture2DArray / UnitySamplerState (the fields Unity's Texture.hlsl declares, as
crates/runtime/tests/engine_shaders.rs does for glslang). Slang's HLSL front end parses and
type-checks them, and its CPU target generates code for each probe (slangpy's CPU device:
no GPU needed; neither DXC nor FXC installs on Linux from the registries).

    python scripts/hlsl_slang.py        (with slangpy installed; tests/tests/hlsl_slang.rs runs it)

Prints one line per probe; exits 1 with Slang's diagnostics when one does not compile.
"""

import pathlib
import sys

import slangpy as spy

ROOT = pathlib.Path(__file__).resolve().parent.parent
HLSL = ROOT / "shaders" / "hlsl"

LIBRARY = (HLSL / "nacre.hlsl").read_text(encoding="utf-8")
GRAPH = (HLSL / "unity" / "NacreShaderGraph.hlsl").read_text(encoding="utf-8")
INCLUDE = '#include "../nacre.hlsl"'

PLAIN = LIBRARY + """
Texture3D<float4> lut_r;
Texture3D<float4> lut_t;
SamplerState lut_s;
Texture2DArray<float4> fourier_table;
RWStructuredBuffer<float4> probe_out;
cbuffer Params { NacreFilmLutParams lut_params; NacreFourierParams fourier_params; NacreRoughLutParams rough_params; };
[shader("compute")]
[numthreads(1, 1, 1)]
void main(uint3 id : SV_DispatchThreadID) {
    NacreFilmInput i = nacre_make_film_input(0.5, 300.0, 1.4, 10.0, 1.0, (float3)1.5, (float3)0.0);
    NacreFilmOutput a = nacre_film_lut_colour(lut_r, lut_s, lut_t, lut_s, lut_params, i);
    NacreFilmOutput b = nacre_film_fourier_colour(fourier_table, fourier_params, i);
    float3 e = nacre_rough_lut_sample(lut_r, lut_s, rough_params, 0.5, 0.2, 300.0, 1.4);
    probe_out[id.x] = float4(a.reflectance + a.transmittance + b.reflectance + b.transmittance + e, 1.0);
}
"""

SHIM = """
struct UnityTexture3D { Texture3D<float4> tex; SamplerState samplerstate; };
struct UnityTexture2DArray { Texture2DArray<float4> tex; SamplerState samplerstate; };
struct UnitySamplerState { SamplerState samplerstate; };
"""

if INCLUDE not in GRAPH:
    sys.exit(f"hlsl_slang.py: NacreShaderGraph.hlsl no longer has `{INCLUDE}`")
GRAPH_PROBE = SHIM + GRAPH.replace(INCLUDE, LIBRARY) + """
Texture3D<float4> r;
Texture2DArray<float4> f;
SamplerState s;
RWStructuredBuffer<float4> probe_out;
[shader("compute")]
[numthreads(1, 1, 1)]
void main(uint3 id : SV_DispatchThreadID) {
    UnityTexture3D t;
    t.tex = r;
    t.samplerstate = s;
    UnityTexture2DArray a;
    a.tex = f;
    a.samplerstate = s;
    UnitySamplerState ss;
    ss.samplerstate = s;
    float3 R; float3 T; float3 R2; float3 T2; float3 E;
    NacreFilmLut_float(t, t, ss, float3(32, 640, 8), float2(0, 1500), float2(1.3, 1.45), 1.0, 1.0, 0.5, 300.0, 1.4, R, T);
    NacreFilmFourier_float(a, 160000.0, 1.0, 0.0, float3(0.0017, 0.0019, 0.0022), (float3)1.0, 0.0, 0.5, 300.0, 1.4, 0.0, 1.0, (float3)1.5, (float3)0.0, R2, T2);
    NacreRoughFilmLut_float(t, ss, float4(16, 64, 8, 8), 1000.0, float2(1.2, 2.4), float2(0.01, 1.0), 1.0, 0.5, 0.3, 300.0, 1.4, E);
    probe_out[id.x] = float4(R + T + R2 + T2 + E, 1.0);
}
"""


def main() -> int:
    device = spy.Device(type=spy.DeviceType.cpu, enable_debug_layers=False)
    failures = 0
    for name, source in (("nacre.hlsl", PLAIN), ("unity/NacreShaderGraph.hlsl", GRAPH_PROBE)):
        try:
            module = device.load_module_from_source(name.replace("/", "_").replace(".", "_"), source)
            program = device.link_program([module], [module.entry_point("main")])
            device.create_compute_kernel(program)
        except Exception as e:  # slangpy raises its own error types with Slang's diagnostics
            failures += 1
            print(f"hlsl_slang.py: FAIL {name}: {e}")
            continue
        print(f"hlsl_slang.py: {name} compiles with Slang (slangpy {spy.__version__}, CPU target)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
