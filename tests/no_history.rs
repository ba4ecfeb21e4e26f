//! The project speaks of itself only. No file of the repository tells how it was developed
//! (numbered or relative work sessions, issue numbers, "before this change" stories) or names
//! files outside the repository (planning notes, a `../shared` folder beside a checkout):
//! a clone is read by people who have neither, and history belongs in commit messages.
//!
//! `every_file_speaks_of_the_project_only` reads every text file git tracks (or, where git or
//! its metadata is absent, every file under the root but build outputs) and fails with a
//! `file:line` list of the lines a pattern matches. The matcher's own tests show both ways
//! that it catches planted lines and passes ordinary words that contain the same letters
//! (emission, permission, ParaView's session classes).
//!
//! This file is exempt: its tests hold the planted lines.

use std::path::{Path, PathBuf};
use std::process::Command;

use regex::Regex;

/// What a pattern catches, and the pattern (case-insensitive, on word boundaries).
const PATTERNS: &[(&str, &str)] = &[
    ("a numbered work session", r"\bsessions?\s+\d+"),
    (
        "a work session told relative to another",
        r"\b(this|that|last|next|earlier|previous|later|same)\s+session\b",
    ),
    (
        "a log kept session by session",
        r"\bsession[\s-]+by[\s-]+session\b",
    ),
    ("the planning notes", r"\bMISSION\.md\b"),
    (
        "a path outside the repository",
        r"\.\./shared\b|/work/(shared|main|wt)\b",
    ),
    (
        "an issue number",
        r"\bissue\s*#\s*\d+|\bissue\s+\d+\b|\bthe issue's\b",
    ),
    (
        "a before-and-after story",
        r"\b(before|after|since|until)\s+(this|that)\s+(change|commit|fix|patch|rewrite|refactor(ing)?)\b|\b(before|after|since|until)\s+the\s+(commit|fix|patch|rewrite|refactoring)\b",
    ),
];

/// ParaView's own class names with "Session" in them, blanked before matching so that a line
/// about them (`vtkSMSession 2`, say) never reads as a work session.
const PARAVIEW_NAMES: &[&str] = &[
    "vtkSMSessionProxyManager",
    "vtkSMSessionClient",
    "vtkSMSessionObject",
    "vtkSMSessionBase",
    "vtkSMSession",
    "vtkPVSessionServer",
    "vtkPVSessionCore",
    "vtkPVSessionBase",
    "vtkPVSession",
    "vtkSession",
];

/// Folders whose files are data, not prose: third-party meshes and fuzzing inputs.
const DATA_FOLDERS: &[&str] = &["tests/data/", "fuzz/seeds/", "fuzz/corpus/"];

/// Folders a walk of the tree (without git) leaves out: version control and build outputs.
const SKIPPED_FOLDERS: &[&str] = &[
    ".git",
    "target",
    "build",
    "fuzz/target",
    "fuzz/corpus",
    "fuzz/artifacts",
    "cylvol-demo",
    "__pycache__",
];

/// This file: its tests plant the lines the patterns catch.
const THIS_FILE: &str = "tests/no_history.rs";

/// A line a pattern matched.
#[derive(Debug, PartialEq)]
struct Finding {
    line: usize,
    what: &'static str,
    text: String,
}

struct Matcher {
    patterns: Vec<(&'static str, Regex)>,
}

impl Matcher {
    fn new() -> Self {
        let patterns = PATTERNS
            .iter()
            .map(|(what, p)| {
                (
                    *what,
                    Regex::new(&format!("(?i){p}")).expect("a valid pattern"),
                )
            })
            .collect();
        Matcher { patterns }
    }

    /// What the line tells of the project's history, if anything.
    fn offence(&self, line: &str) -> Option<&'static str> {
        let mut line = line.to_string();
        for name in PARAVIEW_NAMES {
            line = line.replace(name, &" ".repeat(name.len()));
        }
        self.patterns
            .iter()
            .find(|(_, re)| re.is_match(&line))
            .map(|(what, _)| *what)
    }

    fn scan(&self, text: &str) -> Vec<Finding> {
        text.lines()
            .enumerate()
            .filter_map(|(i, line)| {
                self.offence(line).map(|what| Finding {
                    line: i + 1,
                    what,
                    text: line.trim().chars().take(160).collect(),
                })
            })
            .collect()
    }
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The repository's files, relative to its root: those git tracks (files of a user's own lying
/// about untracked are not the project's), or a walk of the tree where git cannot say.
fn repository_files(root: &Path) -> Vec<String> {
    let listed = Command::new("git")
        .arg("-C")
        .arg(root)
        .args(["ls-files", "-z"])
        .output();
    match listed {
        Ok(out) if out.status.success() => String::from_utf8_lossy(&out.stdout)
            .split('\0')
            .filter(|p| !p.is_empty())
            .map(str::to_string)
            .collect(),
        _ => {
            let mut files = Vec::new();
            walk(root, "", &mut files);
            files
        }
    }
}

fn walk(root: &Path, relative: &str, files: &mut Vec<String>) {
    let Ok(entries) = std::fs::read_dir(root.join(relative)) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        let path = if relative.is_empty() {
            name.clone()
        } else {
            format!("{relative}/{name}")
        };
        let Ok(kind) = entry.file_type() else {
            continue;
        };
        if kind.is_dir() {
            if !SKIPPED_FOLDERS.iter().any(|s| *s == path || *s == name) {
                walk(root, &path, files);
            }
        } else if kind.is_file() {
            files.push(path);
        }
    }
}

/// Whether the file is prose or code to check: not this file, not data (a Markdown note in a
/// data folder is checked).
fn is_checked(path: &str) -> bool {
    path != THIS_FILE
        && (path.ends_with(".md") || !DATA_FOLDERS.iter().any(|d| path.starts_with(d)))
}

/// The file's text, or `None` for a binary file (a NUL byte, or not UTF-8) or one that is gone.
fn text_of(path: &Path) -> Option<String> {
    let bytes = std::fs::read(path).ok()?;
    if bytes.contains(&0) {
        return None;
    }
    String::from_utf8(bytes).ok()
}

#[test]
fn every_file_speaks_of_the_project_only() {
    let root = root();
    let matcher = Matcher::new();
    let files = repository_files(&root);
    let mut checked = 0;
    let mut report = Vec::new();
    for path in files.iter().filter(|p| is_checked(p)) {
        let Some(text) = text_of(&root.join(path)) else {
            continue;
        };
        checked += 1;
        for f in matcher.scan(&text) {
            report.push(format!("{path}:{}: {} — {}", f.line, f.what, f.text));
        }
    }
    // Not vacuous: the sources and the README were among the files read.
    assert!(
        checked > 50,
        "only {checked} text files read of {}",
        files.len()
    );
    for must in ["README.md", "src/lib.rs", "tests/run_all.sh"] {
        assert!(files.iter().any(|p| p == must), "{must} was not listed");
    }
    assert!(
        report.is_empty(),
        "{} lines tell the project's history or name files outside it \
         (history goes in commit messages):\n{}",
        report.len(),
        report.join("\n")
    );
}

#[test]
fn planted_lines_are_caught() {
    let m = Matcher::new();
    let planted = [
        (
            "measured in session 26 on the old machine",
            "a numbered work session",
        ),
        ("Sessions 14–27 read 0.41 s", "a numbered work session"),
        (
            "as this session found, the grid",
            "a work session told relative to another",
        ),
        (
            "that session's machine was slower",
            "a work session told relative to another",
        ),
        (
            "Next session: the BVH",
            "a work session told relative to another",
        ),
        (
            "every figure, session by session",
            "a log kept session by session",
        ),
        ("a session-by-session log", "a log kept session by session"),
        ("see MISSION.md for the targets", "the planning notes"),
        (
            "cylvol gen ../shared/data/mixer.vtk",
            "a path outside the repository",
        ),
        (
            "read /work/shared/seed/talk.txt",
            "a path outside the repository",
        ),
        ("fixed in issue #12", "an issue number"),
        ("Issue 7 asked for it", "an issue number"),
        ("The issue's target, 0.5 s a frame", "an issue number"),
        (
            "before this change the grid marched",
            "a before-and-after story",
        ),
        ("After that fix it reads 0.4 s", "a before-and-after story"),
        ("since the rewrite, faster", "a before-and-after story"),
    ];
    for (line, what) in planted {
        assert_eq!(m.offence(line), Some(what), "{line:?}");
    }
    let text = "fine\nsecond line, session 3\nfine\n";
    assert_eq!(
        m.scan(text),
        vec![Finding {
            line: 2,
            what: "a numbered work session",
            text: "second line, session 3".into()
        }]
    );
}

#[test]
fn ordinary_words_pass() {
    let m = Matcher::new();
    let ordinary = [
        "emission-absorption compositing",
        "Permission denied: the folder takes no file",
        "the transmission of a constant medium",
        "an obsession with 2 cells",
        "vtkSMSession::GetSession() and vtkPVSession 2",
        "vtkSMSessionProxyManager 4 proxies",
        "each pvserver session composites its ranks with IceT",
        "a ParaView session loads the plugin",
        "cylvol gen tests/data/mixer.vtk --refine 4",
        "it issues a warning on standard error",
        "fill=\"#336699\"",
        "the sample before this one",
        "the step before the change of transfer function is drawn",
        "the mission of a mapper",
    ];
    for line in ordinary {
        assert_eq!(m.offence(line), None, "{line:?}");
    }
}

#[test]
fn data_and_this_file_are_exempt_but_notes_beside_data_are_not() {
    assert!(!is_checked(THIS_FILE));
    assert!(!is_checked("tests/data/hexa.vtk"));
    assert!(!is_checked("fuzz/seeds/read_vtu/a.vtu"));
    assert!(is_checked("tests/data/README.md"));
    assert!(is_checked("docs/benchmarks.md"));
    assert!(is_checked("src/lib.rs"));
}

#[test]
fn the_walk_without_git_finds_files_and_skips_build_outputs() {
    let dir = tempfile::tempdir().unwrap();
    for (path, text) in [
        ("README.md", "about\n"),
        ("src/a.rs", "// fine\n// session 9 measured it\n"),
        ("target/release/notes.txt", "session 1\n"),
        (".git/HEAD", "ref\n"),
    ] {
        let p = dir.path().join(path);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, text).unwrap();
    }
    let mut files = Vec::new();
    walk(dir.path(), "", &mut files);
    files.sort();
    assert_eq!(files, vec!["README.md".to_string(), "src/a.rs".to_string()]);
    let text = text_of(&dir.path().join("src/a.rs")).unwrap();
    assert_eq!(Matcher::new().scan(&text).len(), 1);
}
