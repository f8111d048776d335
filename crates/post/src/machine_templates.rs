//! A machine file's own header and footer (`[post] header`, `footer`): NC
//! templates that take the place of the dialect's, checked when the machine
//! file is loaded, as a dialect file's templates are, so that a mistake is
//! reported at its place in the machine file before a post reaches it.

use kinpost_diag::{Diagnostic, Diagnostics, Severity};
use kinpost_nc::{TemplateKind, check_template, template_span_in_toml};
use serde::Deserialize;
use toml::Spanned;

#[derive(Deserialize)]
struct RawFile {
    post: Option<RawPost>,
}

#[derive(Deserialize)]
struct RawPost {
    header: Option<Spanned<String>>,
    footer: Option<Spanned<String>>,
}

/// Checks the `[post] header` and `footer` templates of the machine file
/// `source` (named `file` in diagnostics): their syntax, and that they read
/// only the variables the NC writer gives a header or footer. Every error
/// names the file, line and column of the mistake inside the template.
/// (A file that is not TOML has nothing to check here: its loader reports
/// it.)
pub fn check_machine_templates(source: &str, file: &str) -> Result<(), Diagnostics> {
    let Ok(RawFile { post: Some(post) }) = toml::from_str::<RawFile>(source) else {
        return Ok(());
    };
    let errors: Vec<Diagnostic> = [
        (TemplateKind::Header, post.header),
        (TemplateKind::Footer, post.footer),
    ]
    .into_iter()
    .filter_map(|(kind, t)| {
        let t = t?;
        let e = check_template(kind, t.get_ref()).err()?;
        let span = template_span_in_toml(source, t.span(), t.get_ref(), e.range);
        Some(Diagnostic::at_byte_span(
            Severity::Error,
            file,
            source,
            span,
            format!("[post] {}", e.message),
        ))
    })
    .collect();
    if errors.is_empty() {
        Ok(())
    } else {
        Err(Diagnostics(errors))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_misspelt_variable_is_found_in_the_file() {
        let source = "name = \"m\"\n[post]\ndialect = \"sinumerik\"\nheader = \"\"\"\n; {{ program_name }}\nT{{ tool_numbr }}\n\"\"\"\n";
        let e = check_machine_templates(source, "m.toml").unwrap_err();
        assert_eq!(e.0.len(), 1);
        let d = &e.0[0];
        assert_eq!(d.location(), "m.toml:6:5", "{d}");
        assert!(
            d.to_string().contains("unknown variable `tool_numbr`"),
            "{d}"
        );
        assert!(d.to_string().contains("T{{ tool_numbr }}"), "{d}");
    }

    #[test]
    fn a_syntax_error_is_found_in_the_file() {
        let source = "[post]\nfooter = \"M30\\n{% if x %}\"\n";
        let e = check_machine_templates(source, "m.toml").unwrap_err();
        let d = &e.0[0];
        assert!(d.location().starts_with("m.toml:2:"), "{d}");
        assert!(
            d.to_string()
                .contains("[post] template `footer`: syntax error"),
            "{d}"
        );
    }

    proptest::proptest! {
        /// Any template text: no panic, and every error points at a line
        /// and column of the file.
        #[test]
        fn any_template_is_checked_without_a_panic(
            header in "[ -~\n{}%#]{0,60}",
            footer in "[ -~{}%]{0,30}",
        ) {
            let source = format!(
                "name = \"m\"\n[post]\nheader = '''\n{header}'''\nfooter = '{footer}'\n"
            );
            if let Err(e) = check_machine_templates(&source, "m.toml") {
                let lines = source.split('\n').count();
                for d in &e.0 {
                    proptest::prop_assert!(d.line >= 1 && d.line <= lines && d.column >= 1, "{d}");
                }
            }
        }
    }

    #[test]
    fn the_built_in_machines_templates_are_right() {
        for name in kinpost_machine::builtin::names() {
            let source = kinpost_machine::builtin::source(name).unwrap();
            assert!(check_machine_templates(source, name).is_ok(), "{name}");
        }
        assert!(check_machine_templates("not toml [", "x").is_ok());
        assert!(check_machine_templates("name = \"m\"\n", "x").is_ok());
    }
}
