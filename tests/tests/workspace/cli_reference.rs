//! The command line's reference, generated from its clap definitions:
//! `docs/reference/cli.md` (clap-markdown) and the man page
//! `docs/reference/rtgi.1` (clap_mangen). The test below renders both and
//! compares them with the committed files, so that the reference says what
//! `--help` says; `RTGI_BLESS=1` rewrites them:
//!
//! ```sh
//! RTGI_BLESS=1 cargo test -p rtgi-tests --test workspace cli_reference
//! ```
//!
//! Both generators are dev-dependencies of the tests, so the binary carries
//! neither; the definitions come from [`rtgi::command`].

// With the embree feature the comparison with the committed files is not
// compiled (see the test), so what only it uses goes unused there.
#![cfg_attr(feature = "embree", allow(dead_code))]

use std::path::{Path, PathBuf};

/// Where the reference lives, from the tests' folder.
fn reference_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/reference")
}

/// The command as the reference describes it. clap asks the terminal's
/// width when it wraps help; the reference must not depend on where it was
/// generated, so the width is fixed.
fn command() -> clap::Command {
    rtgi::command().term_width(100)
}

/// `docs/reference/cli.md`: every command with its arguments, options,
/// defaults and possible values.
fn cli_markdown() -> String {
    let options = clap_markdown::MarkdownOptions::new()
        .title("The `rtgi` command line".to_owned())
        // The footer advertises the generator; the header below says how
        // the page is made instead.
        .show_footer(false);
    let mut body = clap_markdown::help_markdown_command_custom(&command(), &options);
    // The generator leaves runs of blank lines between commands and at the
    // end; one blank line reads the same and diffs cleaner.
    while body.contains("\n\n\n") {
        body = body.replace("\n\n\n", "\n\n");
    }
    let body = format!("{}\n", body.trim_end());
    // The generator's title comes first; the note goes after it.
    let (title, rest) = body.split_once('\n').unwrap_or((&body, ""));
    format!(
        "{title}\n\n<!-- Generated from apps/rtgi/src/cli.rs by tests/tests/workspace/cli_reference.rs: do not \
         edit; RTGI_BLESS=1 cargo test -p rtgi-tests --test workspace cli_reference rewrites it. -->\n\nThis reference is generated from \
         the command's definitions, so it says what `rtgi --help` says. The [guide](../guide/README.md) \
         explains the commands with examples; `man docs/reference/rtgi.1` is the same reference as a man \
         page.\n{rest}"
    )
}

/// `docs/reference/rtgi.1`: the man page of `rtgi`, with a section per
/// command. clap_mangen writes one page per command; one page is what a
/// newcomer opens, so the commands' synopses, descriptions and options are
/// appended to the top page, their section headings made subsections.
fn man_page() -> String {
    let command = command();
    // No date: the page would change on every day it is generated.
    let man = |command: clap::Command| clap_mangen::Man::new(command).date("").manual("rtgi manual");
    let mut top = Vec::new();
    man(command.clone()).render(&mut top).expect("writing to memory");
    let mut page = String::from_utf8(top).expect("roff is UTF-8");
    for sub in command.get_subcommands().filter(|sub| !sub.is_hide_set()) {
        // The list of commands points at a page per command (`rtgi-render(1)`),
        // which is not written: it names the section below instead.
        let roff = |text: String| text.replace('-', "\\-");
        page = page.replace(
            &roff(format!("{}-{}(1)", command.get_name(), sub.get_name())),
            &roff(format!("\\fB{} {}\\fR", command.get_name(), sub.get_name())),
        );
        // A subcommand knows its own name only; its synopsis should read
        // `rtgi render ...`.
        let full = sub.clone().bin_name(format!("{} {}", command.get_name(), sub.get_name()));
        let mut section = Vec::new();
        let sub_man = man(full);
        sub_man.render_synopsis_section(&mut section).expect("writing to memory");
        sub_man.render_description_section(&mut section).expect("writing to memory");
        sub_man.render_options_section(&mut section).expect("writing to memory");
        let section = String::from_utf8(section).expect("roff is UTF-8");
        page.push_str(&format!(".SH \"COMMAND: {} {}\"\n", command.get_name(), sub.get_name()));
        page.push_str(&section.replace(".SH ", ".SS "));
    }
    // clap's own `help` command, which prints what this page says.
    page.replace("rtgi\\-help(1)", "\\fBrtgi help\\fR")
}

/// Compares `generated` with the committed file, or writes it when
/// `RTGI_BLESS` is set. Returns what differs, for the test to report.
fn check(name: &str, generated: &str) -> Option<String> {
    let path = reference_dir().join(name);
    if std::env::var_os("RTGI_BLESS").is_some() {
        std::fs::create_dir_all(reference_dir()).expect("docs/reference created");
        std::fs::write(&path, generated).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        return None;
    }
    let Ok(committed) = std::fs::read_to_string(&path) else {
        return Some(format!("docs/reference/{name} is missing"));
    };
    if committed == generated {
        return None;
    }
    let line = generated.lines().zip(committed.lines()).position(|(a, b)| a != b);
    Some(format!(
        "docs/reference/{name} differs from what the command's definitions give (first at {})",
        line.map_or("its end".to_owned(), |l| format!("line {}", l + 1))
    ))
}

// The reference describes the default build, which the README's test
// command builds; with the embree feature `--accel` lists one more
// structure (its help says so), and the committed files would differ.
#[cfg(not(feature = "embree"))]
#[test]
fn the_committed_reference_is_the_commands_definitions() {
    let problems: Vec<String> =
        [("cli.md", cli_markdown()), ("rtgi.1", man_page())].iter().filter_map(|(n, g)| check(n, g)).collect();
    assert!(
        problems.is_empty(),
        "{}\nthe reference is generated, never edited by hand: rewrite it with \
         RTGI_BLESS=1 cargo test -p rtgi-tests --test workspace cli_reference",
        problems.join("\n")
    );
}

#[test]
fn the_reference_names_every_command_and_is_the_same_each_time() {
    let (markdown, man) = (cli_markdown(), man_page());
    for sub in command().get_subcommands().filter(|sub| !sub.is_hide_set()) {
        let name = sub.get_name();
        assert!(markdown.contains(&format!("## `rtgi {name}`")), "cli.md has no section for {name}");
        assert!(man.contains(&format!(".SH \"COMMAND: rtgi {name}\"")), "rtgi.1 has no section for {name}");
    }
    // One page: no reference to a page per command that is not written.
    assert!(
        !man.contains("(1)"),
        "rtgi.1 points at another page: {}",
        man.lines().find(|l| l.contains("(1)")).unwrap()
    );
    // Generated twice in one process, it must not differ: a date, a map's
    // order or the terminal's width would make the committed file stale.
    assert_eq!((markdown, man), (cli_markdown(), man_page()));
}
