//! Tests of the module table, the import resolver and the source maps.

use super::*;

#[test]
fn the_table_matches_the_directory() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shaders");
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "wgsl"))
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .collect();
    files.sort();
    let mut names: Vec<String> = MODULES.iter().map(|m| m.name.to_string()).collect();
    names.sort();
    assert_eq!(names, files);
    for m in MODULES {
        let text = std::fs::read_to_string(dir.join(format!("{}.wgsl", m.name))).unwrap();
        assert_eq!(
            text, m.source,
            "{}: table source differs from the file",
            m.name
        );
    }
}

/// The declared dependencies of every module, as its header states them.
#[test]
fn every_header_declares_its_imports() {
    let expected: &[(&str, &[&str])] = &[
        ("common", &[]),
        ("lut_mapping", &["common"]),
        ("film_lut", &["common", "lut_mapping"]),
        ("film_fourier", &["common"]),
        ("film_spectral", &["common"]),
        ("film_stack", &["common"]),
        ("plain", &["common"]),
        ("rough_lut_mapping", &[]),
        ("output", &[]),
        ("view", &["rough_lut_mapping"]),
        (
            "material",
            &[
                "common",
                "<technique>",
                "rough_lut_mapping",
                "view",
                "output",
            ],
        ),
        ("scene", &["material"]),
        ("mesh", &["material"]),
        ("mip_down", &[]),
        ("probe", &["common", "<technique>"]),
        ("bench", &["common", "<technique>"]),
        ("diffraction_common", &[]),
        ("diffraction", &["diffraction_common"]),
        ("diffraction_integrated", &["diffraction_common"]),
        (
            "diffraction_integrated_technique",
            &["diffraction_integrated"],
        ),
        (
            "diffraction_scene",
            &["diffraction_common", "<technique>", "view", "output"],
        ),
        ("diffraction_integrated_probe", &["diffraction_integrated"]),
    ];
    // Every module is listed here but a new technique of the registry, which imports
    // only shared modules.
    for m in MODULES {
        if expected.iter().all(|(name, _)| *name != m.name) {
            assert!(
                REGISTRY.iter().any(|e| e.module == m.name),
                "{}: not listed",
                m.name
            );
            for import in m.imports().unwrap() {
                assert!(
                    matches!(import, Import::Module(d) if SHARED_MODULES.iter().any(|s| s.name == d)),
                    "{}: imports {import}",
                    m.name
                );
            }
        }
    }
    for (name, deps) in expected {
        let m = module(name).unwrap_or_else(|| panic!("no module {name}"));
        let header_lines = m
            .source
            .lines()
            .take_while(|l| l.starts_with("//"))
            .filter(|l| l.starts_with("// import:"))
            .count();
        assert_eq!(header_lines, 1, "{name}: one `// import:` line");
        let imports: Vec<String> = m.imports().unwrap().iter().map(|i| i.to_string()).collect();
        assert_eq!(imports, *deps, "{name}");
        for import in m.imports().unwrap() {
            if let Import::Module(dep) = import {
                assert!(module(dep).is_some(), "{name} imports unknown {dep}");
            }
        }
    }
}

#[test]
fn header_syntax() {
    // The syntax is tested with its reader, `nacre_format::wgsl_header`; here, that the
    // composer reads it and reports a bad line as a `ComposeError`.
    assert_eq!(
        parse_imports("x", "// import: a, <technique>\nfn f() {}\n").unwrap(),
        [Import::Module("a"), Import::Technique]
    );
    assert_eq!(
        parse_imports("x", "// t\n// import: a b\n"),
        Err(ComposeError::BadImport {
            module: "x".into(),
            line: 2,
            text: "// import: a b".into()
        })
    );
}

fn src<'a>(label: &'a str, source: &'a str) -> Part<'a> {
    Part::Source { label, source }
}

#[test]
fn resolver_orders_depth_first_once_each() {
    let c = src("c", "// import: diffraction_common\nfn c() {}");
    let roots = [c, Part::Module("diffraction"), c];
    let composed = resolve(&roots, None).unwrap();
    let files: Vec<&str> = composed.map.spans.iter().map(|s| s.file.as_str()).collect();
    assert_eq!(files, ["diffraction_common.wgsl", "c", "diffraction.wgsl"]);
    let dc = module("diffraction_common").unwrap().source;
    let d = module("diffraction").unwrap().source;
    assert_eq!(
        composed.source,
        format!("{dc}\n// import: diffraction_common\nfn c() {{}}\n{d}\n")
    );
    for s in &composed.map.spans {
        assert!(composed.source[s.bytes.clone()].ends_with(['}', '\n']));
    }
}

#[test]
fn resolver_reports_cycles_unknown_names_and_missing_techniques() {
    let table = [
        Module {
            name: "x",
            source: "// import: y\n",
        },
        Module {
            name: "y",
            source: "// import: <technique>\n",
        },
        Module {
            name: "z",
            source: "// import: (none)\n",
        },
    ];
    assert_eq!(
        resolve_in(&table, &[Part::Module("x")], Some(Part::Module("x"))),
        Err(ComposeError::Cycle {
            cycle: vec!["x.wgsl".into(), "y.wgsl".into(), "x.wgsl".into()]
        })
    );
    let composed = resolve_in(&table, &[Part::Module("x")], Some(Part::Module("z"))).unwrap();
    assert_eq!(
        composed.source,
        "// import: (none)\n\n// import: <technique>\n\n// import: y\n\n"
    );
    let b = src("b", "// import: <technique>\nfn b() {}");
    assert_eq!(
        resolve(&[b], Some(b)),
        Err(ComposeError::Cycle {
            cycle: vec!["b".into(), "b".into()]
        })
    );
    let u = src("u", "// import: common, nowhere\n");
    assert_eq!(
        resolve(&[u], None),
        Err(ComposeError::UnknownModule {
            importer: "u".into(),
            name: "nowhere".into()
        })
    );
    assert_eq!(
        flatten("scene"),
        Err(ComposeError::NoTechnique {
            importer: "material.wgsl".into()
        })
    );
    assert!(matches!(
        flatten("nope"),
        Err(ComposeError::UnknownModule { .. })
    ));
    let message = ComposeError::Cycle {
        cycle: vec!["a".into(), "b".into(), "a".into()],
    }
    .to_string();
    assert_eq!(message, "import cycle: a → b → a");
}

/// The compositions the runtime used before the import headers, by hand: each part
/// followed by a newline, `MATERIAL` = rough_lut_mapping + view + output + material.
#[test]
fn compositions_are_the_historical_concatenations() {
    let cat = |parts: &[&str]| parts.iter().map(|p| format!("{p}\n")).collect::<String>();
    for t in Technique::ALL {
        let head = [COMMON, LUT_MAPPING, t.source()];
        let with = |tail: &[&str]| cat(&[&head[..], tail].concat());
        assert_eq!(compose(t, &[PROBE]), with(&[PROBE]));
        assert_eq!(compose(t, &[BENCH]), with(&[BENCH]));
        assert_eq!(
            compose(t, &[MATERIAL, SCENE]),
            with(&[ROUGH_LUT_MAPPING, VIEW, OUTPUT, MATERIAL, SCENE])
        );
        assert_eq!(
            compose(t, &[MATERIAL, MESH]),
            with(&[ROUGH_LUT_MAPPING, VIEW, OUTPUT, MATERIAL, MESH])
        );
        assert_eq!(
            film_pipeline(t.module(), &["scene"]).unwrap().source,
            with(&[ROUGH_LUT_MAPPING, VIEW, OUTPUT, MATERIAL, SCENE])
        );
        assert_eq!(
            film_pipeline(t.module(), &["mesh"]).unwrap().source,
            compose(t, &[MATERIAL, MESH])
        );
        assert_eq!(
            film_pipeline(t.module(), &["probe"]).unwrap().source,
            compose(t, &[PROBE])
        );
    }
    assert_eq!(
        compose_source(PLAIN, &[BENCH]),
        cat(&[COMMON, LUT_MAPPING, PLAIN, BENCH])
    );
    assert_eq!(
        film_pipeline("plain", &["bench"]).unwrap().source,
        compose_source(PLAIN, &[BENCH])
    );
    // A host's consumer that is no module is appended as given.
    let host = "fn host() {}";
    assert_eq!(
        compose(Technique::Lut, &[host]),
        cat(&[COMMON, LUT_MAPPING, Technique::Lut.source(), host])
    );
    let m = try_compose(Technique::Lut.source(), &[MATERIAL, host])
        .unwrap()
        .map;
    let files: Vec<&str> = m.spans.iter().map(|s| s.file.as_str()).collect();
    assert_eq!(
        files,
        [
            "common.wgsl",
            "lut_mapping.wgsl",
            "film_lut.wgsl",
            "rough_lut_mapping.wgsl",
            "view.wgsl",
            "output.wgsl",
            "material.wgsl",
            "consumer 2"
        ]
    );
}

/// The files a host gets (shaders/README.md lists them).
#[test]
fn flattened_techniques() {
    let expected: &[(&str, &[&str])] = &[
        ("film_lut", &["common", "lut_mapping", "film_lut"]),
        ("film_fourier", &["common", "film_fourier"]),
        ("film_spectral", &["common", "film_spectral"]),
        ("film_stack", &["common", "film_stack"]),
        ("plain", &["common", "plain"]),
        ("diffraction", &["diffraction_common", "diffraction"]),
        (
            "diffraction_integrated",
            &["diffraction_common", "diffraction_integrated"],
        ),
    ];
    // Listed here: every technique module but a new technique of the registry, which
    // flattens to `common`, the shared modules it imports, then itself.
    for name in TECHNIQUE_MODULES {
        if expected.iter().all(|e| e.0 != *name) {
            let files = flatten(name).unwrap().map.spans;
            assert_eq!(files[0].file, "common.wgsl", "{name}");
            assert_eq!(files.last().unwrap().file, format!("{name}.wgsl"));
        }
    }
    assert!(expected.iter().all(|e| TECHNIQUE_MODULES.contains(&e.0)));
    for (name, modules) in expected {
        let composed = flatten(name).unwrap();
        let files: Vec<String> = composed.map.spans.iter().map(|s| s.file.clone()).collect();
        let wanted: Vec<String> = modules.iter().map(|m| format!("{m}.wgsl")).collect();
        assert_eq!(files, wanted, "{name}");
    }
}

#[test]
fn source_map_places_lines() {
    let a = src("a.wgsl", "// a\nfn a() {}");
    let b = src("b.wgsl", "// b\n\nfn b() {\n}\n");
    let composed = resolve(&[a, b], None).unwrap();
    // a: lines 1–2 (+ the newline after it ends line 2); b: lines 3–7 (its trailing
    // newline, then the composition's, make line 7 empty).
    assert_eq!(
        composed.map.describe(),
        "lines 1–2 a.wgsl, lines 3–7 b.wgsl"
    );
    let at = |line| composed.map.locate_line(line).map(|l| l.to_string());
    assert_eq!(at(1).as_deref(), Some("a.wgsl:1"));
    assert_eq!(at(2).as_deref(), Some("a.wgsl:2"));
    assert_eq!(at(3).as_deref(), Some("b.wgsl:1"));
    assert_eq!(at(5).as_deref(), Some("b.wgsl:3"));
    assert_eq!(at(8), None);
    let offset = composed.source.find("b() {").unwrap();
    assert_eq!(
        composed.locate_offset(offset).unwrap().to_string(),
        "b.wgsl:3:4"
    );
    assert_eq!(composed.locate_offset(0).unwrap().to_string(), "a.wgsl:1:1");
    assert_eq!(composed.locate_offset(composed.source.len()), None);
    let line5 = composed.source.lines().nth(4).unwrap();
    assert_eq!(line5, "fn b() {");
    assert_eq!(composed.map.locate(5, 4).unwrap().to_string(), "b.wgsl:3:4");
    let info = wgpu::CompilationInfo {
        messages: vec![
            wgpu::CompilationMessage {
                message: "expected `;`".into(),
                message_type: wgpu::CompilationMessageType::Error,
                location: Some(wgpu::SourceLocation {
                    line_number: 5,
                    line_position: 4,
                    offset: 0,
                    length: 1,
                }),
            },
            wgpu::CompilationMessage {
                message: "no position".into(),
                message_type: wgpu::CompilationMessageType::Warning,
                location: None,
            },
        ],
    };
    assert_eq!(
        composed.map.annotate(&info),
        "b.wgsl:3:4: error: expected `;`\nwarning: no position"
    );
}
