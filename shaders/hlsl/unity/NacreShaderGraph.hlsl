// nacre · shaders/hlsl/unity/NacreShaderGraph.hlsl — Unity Shader Graph Custom Function nodes
//
// Entry points for Shader Graph's Custom Function node (Type: File, Source: this file;
// Unity 2022.3 LTS / Shader Graph 14 and Unity 6 / Shader Graph 17, URP or HDRP). Shader Graph
// calls `<Name>_<precision>`: these are the `_float` functions, so set the node's precision
// to Single (or the graph's to Single). Texture ports arrive as Shader Graph's
// `UnityTexture3D` / `UnityTexture2DArray` (fields `tex`, `samplerstate`) and sampler ports
// as `UnitySamplerState` (field `samplerstate`); integer-valued inputs (texel counts, the
// level count, the harmonics) are Float ports, rounded here. A table reaches a texture port
// from a Blackboard Texture 3D / Texture 2D Array property set with material.SetTexture (a
// texture made by a script cannot be a port's default). Clamp the film colour (max(·, 0))
// before lighting: out-of-gamut channels are negative. docs/engines/unity.md lists
// the ports in order and where their values come from (the table's manifest or the sidecar
// of `nacre export`). Everything else is shaders/hlsl/nacre.hlsl, unchanged.
//
// Symbols: the film-lut lookup (nacre_film_lut_colour) reads cos θ (CosTheta), d
// (ThicknessNm), n (FilmIor); the fourier series (nacre_film_fourier_colour, Belcour & Barla
// 2017 Eq. 10) also σ_d (SigmaThicknessNm), n₁ (AmbientIor), ñ₃ = n + iκ per channel (BaseIor,
// BaseKappa); the rough-film-lut albedo (nacre_rough_lut_sample) cos θ_o (CosThetaO), α
// (Alpha = perceptual roughness²), d, n_f.

#ifndef NACRE_SHADER_GRAPH_HLSL
#define NACRE_SHADER_GRAPH_HLSL

#include "../nacre.hlsl"

// Float port → non-negative integer (round to nearest; NaN and negatives → 0).
uint NacreCount(float x) {
    return x > 0.5 ? (uint)(x + 0.5) : 0u;
}

// The film-lut technique: trilinear lookup of a `film-lut` table at (cos θ, d, n).
// Counts = (cos_theta_count, opd_count, ior_count); ThicknessRange = (thickness_min_nm,
// thickness_max_nm); IorRange = (ior_min, ior_max); HasTransmittance = 1 when Transmittance
// holds the table's transmittance (else bind any 3-D texture and pass 0).
void NacreFilmLut_float(UnityTexture3D Reflectance, UnityTexture3D Transmittance, UnitySamplerState Sampler,
    float3 Counts, float2 ThicknessRange, float2 IorRange, float AmbientIndex, float HasTransmittance,
    float CosTheta, float ThicknessNm, float FilmIor,
    out float3 ReflectanceRGB, out float3 TransmittanceRGB)
{
    NacreFilmLutParams p = nacre_make_film_lut_params(uint3(NacreCount(Counts.x), NacreCount(Counts.y), NacreCount(Counts.z)),
        ThicknessRange, IorRange, AmbientIndex, HasTransmittance > 0.5);
    NacreFilmInput i = nacre_make_film_input(CosTheta, ThicknessNm, FilmIor, 0.0, AmbientIndex, (float3)1.5, (float3)0.0);
    NacreFilmOutput o = nacre_film_lut_colour(Reflectance.tex, Sampler.samplerstate, Transmittance.tex, Sampler.samplerstate, p, i);
    ReflectanceRGB = o.reflectance;
    TransmittanceRGB = o.transmittance;
}

// The fourier technique: Belcour & Barla 2017 Eq. 10 with exact Fresnel over a `fourier`
// table. MaxOpdNm = max_opd_nm; LevelCount = the number of levels (≤ the texture's mips);
// Sigma1Nm = level_sigma_nm[1] (0 with one level); Carrier = ν̄_j (1/nm); White = ‖s_j‖;
// Harmonics = M (0 = automatic, the runtime's default; a positive M is a fixed count).
void NacreFilmFourier_float(UnityTexture2DArray Table,
    float MaxOpdNm, float LevelCount, float Sigma1Nm, float3 Carrier, float3 White, float Harmonics,
    float CosTheta, float ThicknessNm, float FilmIor, float SigmaThicknessNm, float AmbientIor, float3 BaseIor, float3 BaseKappa,
    out float3 ReflectanceRGB, out float3 TransmittanceRGB)
{
    NacreFourierParams p = nacre_make_fourier_params(MaxOpdNm, NacreCount(LevelCount), Sigma1Nm, Carrier, White, NacreCount(Harmonics));
    NacreFilmInput i = nacre_make_film_input(CosTheta, ThicknessNm, FilmIor, SigmaThicknessNm, AmbientIor, BaseIor, BaseKappa);
    NacreFilmOutput o = nacre_film_fourier_colour(Table.tex, p, i);
    ReflectanceRGB = o.reflectance;
    TransmittanceRGB = o.transmittance;
}

// The rough-film-lut albedo E (reflected E_r or transmitted E_t, whichever Table holds) at
// (cos θ_o, α, d, n_f). Counts = (cos_theta_count, opd_count, ior_count, alpha_count);
// IorRange = (ior_min, ior_max); AlphaRange = (alpha_min, alpha_max).
void NacreRoughFilmLut_float(UnityTexture3D Table, UnitySamplerState Sampler,
    float4 Counts, float ThicknessMaxNm, float2 IorRange, float2 AlphaRange, float AmbientIndex,
    float CosThetaO, float Alpha, float ThicknessNm, float FilmIor,
    out float3 Albedo)
{
    NacreRoughLutParams p = nacre_make_rough_lut_params(
        uint4(NacreCount(Counts.x), NacreCount(Counts.y), NacreCount(Counts.z), NacreCount(Counts.w)),
        ThicknessMaxNm, IorRange, AlphaRange, AmbientIndex, true);
    Albedo = nacre_rough_lut_sample(Table.tex, Sampler.samplerstate, p, CosThetaO, Alpha, ThicknessNm, FilmIor);
}

#endif
