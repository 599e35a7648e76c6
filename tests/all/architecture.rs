//! docs/architecture.md matches src/ (issue 27): every module of the crate (each top-level
//! file `x.rs`, each folder `x/`, nested folders `x/y/`) has a row in the page's Modules table,
//! and every row names a module that exists. `lib.rs` is the crate root, not a row.

use std::collections::BTreeSet;
use std::path::Path;

/// The modules under `src/` as the page names them: `x.rs` for a top-level file, `x/` and
/// `x/y/` for folders (relative to `src/`, `/`-separated).
fn modules_of_src(src: &Path) -> BTreeSet<String> {
    fn walk(dir: &Path, prefix: &str, out: &mut BTreeSet<String>) {
        let mut entries: Vec<_> = std::fs::read_dir(dir).unwrap_or_else(|e| panic!("reading {}: {e}", dir.display())).map(|e| e.expect("directory entry").path()).collect();
        entries.sort();
        for p in entries {
            let name = p.file_name().expect("a file name").to_string_lossy().into_owned();
            if p.is_dir() {
                let rel = format!("{prefix}{name}/");
                out.insert(rel.clone());
                walk(&p, &rel, out);
            } else if prefix.is_empty() && name.ends_with(".rs") && name != "lib.rs" {
                out.insert(name);
            }
        }
    }
    let mut out = BTreeSet::new();
    walk(src, "", &mut out);
    out
}

/// The first cell of each row of the page's `## Modules` table, without its backticks.
fn modules_on_page(page: &str) -> BTreeSet<String> {
    let section = page.split("\n## Modules").nth(1).expect("docs/architecture.md has a `## Modules` section");
    let section = section.split("\n## ").next().unwrap_or(section);
    section
        .lines()
        .filter(|l| l.starts_with("| `"))
        .filter_map(|l| l.split('|').nth(1))
        .map(|cell| cell.trim().trim_matches('`').to_string())
        .collect()
}

#[test]
fn every_module_of_src_is_on_the_architecture_page() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let page_path = root.join("docs/architecture.md");
    let page = std::fs::read_to_string(&page_path).unwrap_or_else(|e| panic!("reading {}: {e}", page_path.display()));
    let in_src = modules_of_src(&root.join("src"));
    let on_page = modules_on_page(&page);
    // a sanity floor so that a broken walk or a renamed section cannot pass vacuously
    assert!(in_src.len() >= 20 && in_src.contains("pipeline.rs") && in_src.contains("problem/reservoir/"), "walk of src/ found {in_src:?}");
    let missing: Vec<&String> = in_src.difference(&on_page).collect();
    let gone: Vec<&String> = on_page.difference(&in_src).collect();
    assert!(missing.is_empty(), "modules of src/ missing from the Modules table of docs/architecture.md (add a row `| `name` | job | may import |`): {missing:?}");
    assert!(gone.is_empty(), "rows of the Modules table of docs/architecture.md name modules that are not in src/ (remove or rename them): {gone:?}");
}

/// The test's parser on a page that lacks a module: it must name it.
#[test]
fn a_module_missing_from_the_page_is_named() {
    let page = "# x\n\n## Modules\n\n| module | job | may import |\n|---|---|---|\n| `pipeline.rs` | the recipe | error |\n\n## Next\n| `not_a_row.rs` | x | y |\n";
    let on_page = modules_on_page(page);
    assert_eq!(on_page, BTreeSet::from(["pipeline.rs".to_string()]));
    let in_src = modules_of_src(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"));
    assert!(in_src.difference(&on_page).any(|m| m == "simulation.rs"), "simulation.rs would be reported missing");
}
