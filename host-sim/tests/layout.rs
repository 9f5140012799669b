//! host-sim by concern: the engine stands alone. Nothing in `engine/`
//! reaches into the scope, the studies or processor in the loop, so a
//! headless user, a study or a test takes the engine without them.

use std::path::Path;

#[test]
fn the_engine_imports_neither_the_scope_nor_the_studies() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/engine");
    let mut files = 0;
    // The engine's files, its sub-folders' (xyz/) too.
    let mut paths = vec![dir.clone()];
    let mut sources = Vec::new();
    while let Some(d) = paths.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                paths.push(path);
            } else {
                sources.push(path);
            }
        }
    }
    for path in sources {
        let text = std::fs::read_to_string(&path).unwrap();
        for banned in ["crate::scope", "crate::study", "crate::pil", "egui"] {
            assert!(!text.contains(banned), "{} uses {banned}", path.display());
        }
        files += 1;
    }
    assert!(files >= 7, "{files} files in {}", dir.display());
}
