//! Replays every input the fuzzers crashed on (`fuzz/regressions/TARGET/*`,
//! see `.ci/fuzz`) through the fuzz target's body in `zoovr::fuzzing`, so a
//! fixed crash stays fixed. Also checks that every target folder names a
//! real target.

use std::path::Path;

use zoovr::fuzzing::TARGETS;

#[test]
fn every_kept_crash_input_passes() {
    let root = zoovr::testdata::project_root().join("fuzz/regressions");
    let mut replayed = 0;
    for entry in std::fs::read_dir(&root).expect("fuzz/regressions") {
        let dir = entry.unwrap().path();
        let name = dir.file_name().unwrap().to_string_lossy().into_owned();
        let (_, body) = TARGETS
            .iter()
            .find(|(n, _)| *n == name)
            .unwrap_or_else(|| panic!("fuzz/regressions/{name}: no such fuzz target"));
        for file in std::fs::read_dir(&dir).unwrap() {
            let file = file.unwrap().path();
            let data = std::fs::read(&file).unwrap();
            eprintln!("{name}: {}", short(&file));
            body(&data);
            replayed += 1;
        }
    }
    assert!(replayed >= 2, "only {replayed} inputs");
}

fn short(p: &Path) -> String {
    p.file_name().unwrap().to_string_lossy().into_owned()
}

/// The fuzz crate builds exactly the targets `zoovr::fuzzing` lists.
#[test]
fn fuzz_manifest_lists_every_target() {
    let toml =
        std::fs::read_to_string(zoovr::testdata::project_root().join("fuzz/Cargo.toml")).unwrap();
    for (name, _) in TARGETS {
        assert!(
            toml.contains(&format!("name = \"{name}\"")),
            "fuzz/Cargo.toml lacks {name}"
        );
        let src = zoovr::testdata::project_root().join(format!("fuzz/fuzz_targets/{name}.rs"));
        let text = std::fs::read_to_string(&src).unwrap();
        assert!(text.contains(&format!("zoovr::fuzzing::{name}(data)")));
    }
}
