//! The README lists every control: each key binding (as the help shows its keys) and each
//! mouse action of the window's one key table, so a key added to the table without the
//! README fails here.

use viewer::window::keys::{BINDINGS, MOUSE_HELP};

fn readme() -> String {
    let p = concat!(env!("CARGO_MANIFEST_DIR"), "/../../README.md");
    std::fs::read_to_string(p).expect("README.md")
}

#[test]
fn the_readme_lists_every_key_and_mouse_action() {
    let text = readme();
    let rows: Vec<&str> = text.lines().filter(|l| l.starts_with("| ")).collect();
    for b in BINDINGS {
        let keys = format!("| {} |", b.keys_label());
        assert!(
            rows.iter().any(|r| r.starts_with(&keys)),
            "README.md has no row for {keys} ({})",
            b.help
        );
    }
    for (input, _) in MOUSE_HELP {
        let row = format!("| {input} |");
        assert!(
            rows.iter().any(|r| r.starts_with(&row)),
            "README.md has no row for {row}"
        );
    }
}

#[test]
fn the_readme_examples_use_files_in_the_repository() {
    let text = readme();
    assert!(
        !text.contains("../shared"),
        "an example points outside the repository"
    );
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
    // Every repository path an example names exists.
    for word in text.split(|c: char| c.is_whitespace() || c == '`' || c == '(' || c == ')') {
        let path = word.split('@').next().unwrap_or(word);
        let path = path.trim_end_matches([',', '.', ':']);
        if ["assets/", "tests/data/"]
            .iter()
            .any(|p| path.starts_with(p))
        {
            assert!(
                std::path::Path::new(root).join(path).exists(),
                "README.md names {path}, which is not in the repository"
            );
        }
    }
}
