//! Filling the `{{NAME}}` placeholders of a modelDescription template.
//!
//! A placeholder takes either text (escaped for an attribute value) or an XML fragment. A
//! fragment whose placeholder stands alone on its line is indented like that line, one line of
//! the fragment per line; an empty fragment removes the line.

use crate::error::HarnessError;

#[derive(Debug, Clone, Copy)]
pub enum Fill<'a> {
    /// Text, escaped for use inside an attribute value.
    Text(&'a str),
    /// A well-formed XML fragment, inserted as is.
    Xml(&'a str),
}

/// The template with every placeholder replaced; an unknown or unclosed placeholder is an error,
/// and so is text that XML 1.0 cannot hold (a control character but tab, line feed and carriage
/// return, U+FFFE, U+FFFF: the scene's rule `xml_text` refuses them first, this keeps the
/// packager from writing a document no parser reads, whatever it is given).
pub fn fill(template: &str, values: &[(&str, Fill)]) -> Result<String, HarnessError> {
    let mut out = String::with_capacity(template.len() * 2);
    let mut rest = template;
    while let Some(open) = rest.find("{{") {
        let after = &rest[open + 2..];
        let close = after.find("}}").ok_or_else(|| HarnessError::Template {
            message: format!(
                "unclosed placeholder near {:?}",
                truncate(&rest[open..], 40)
            ),
        })?;
        let name = &after[..close];
        let value = values
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, v)| *v)
            .ok_or_else(|| HarnessError::Template {
                message: format!("unknown placeholder {{{{{name}}}}}"),
            })?;
        out.push_str(&rest[..open]);
        rest = &after[close + 2..];
        match value {
            Fill::Text(t) => {
                if let Some(c) = t.chars().find(|&c| !fmu_beam::scene::rules::xml_char(c)) {
                    return Err(HarnessError::Template {
                        message: format!(
                            "{{{{{name}}}}}: the text holds U+{:04X}, which XML 1.0 cannot hold",
                            c as u32
                        ),
                    });
                }
                out.push_str(&escape_attribute(t))
            }
            Fill::Xml(x) => {
                let line_start = out.rfind('\n').map_or(0, |i| i + 1);
                let indent = &out[line_start..];
                let line_end = rest.find('\n').unwrap_or(rest.len());
                let alone = indent.trim().is_empty() && rest[..line_end].trim().is_empty();
                if alone {
                    let indent = indent.to_string();
                    out.truncate(line_start);
                    for line in x.lines().filter(|l| !l.trim().is_empty()) {
                        out.push_str(&indent);
                        out.push_str(line);
                        out.push('\n');
                    }
                    rest = rest.get(line_end + 1..).unwrap_or("");
                } else {
                    out.push_str(x);
                }
            }
        }
    }
    out.push_str(rest);
    Ok(out)
}

/// Text made safe for a double-quoted XML attribute value: `&`, `<`, `>` and `"` escaped, tabs
/// and line breaks turned into spaces (an XML parser would normalize them so), other control
/// characters (not allowed in XML 1.0) dropped.
pub fn escape_attribute(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\t' | '\n' | '\r' => out.push(' '),
            c if c.is_control() => {}
            c => out.push(c),
        }
    }
    out
}

fn truncate(s: &str, n: usize) -> &str {
    match s.char_indices().nth(n) {
        Some((i, _)) => &s[..i],
        None => s,
    }
}

#[cfg(test)]
mod tests {
    use super::{fill, Fill};

    #[test]
    fn text_is_escaped_and_fragments_are_indented() {
        let t = "<a x=\"{{X}}\">\n  {{BODY}}\n  {{EMPTY}}\n</a>\n";
        let out = fill(
            t,
            &[
                ("X", Fill::Text("1 < 2 & \"q\"\n")),
                ("BODY", Fill::Xml("<b>\n  <c/>\n</b>")),
                ("EMPTY", Fill::Xml("")),
            ],
        )
        .unwrap();
        assert_eq!(
            out,
            "<a x=\"1 &lt; 2 &amp; &quot;q&quot; \">\n  <b>\n    <c/>\n  </b>\n</a>\n"
        );
    }

    #[test]
    fn text_xml_cannot_hold_is_refused_naming_the_placeholder() {
        for bad in ["a\u{FFFE}b", "\u{FFFF}", "bell\u{7}"] {
            let e = fill(
                "<a x=\"{{DESCRIPTION}}\"/>",
                &[("DESCRIPTION", Fill::Text(bad))],
            )
            .unwrap_err()
            .to_string();
            assert!(
                e.contains("{{DESCRIPTION}}") && e.contains("XML 1.0"),
                "{e}"
            );
        }
        let ok = fill(
            "<a x=\"{{D}}\"/>",
            &[("D", Fill::Text("tab\there, é, \u{10FFFF}"))],
        );
        assert!(ok.is_ok());
    }

    #[test]
    fn unknown_and_unclosed_placeholders_are_refused() {
        let e = fill("{{NOPE}}", &[]).unwrap_err().to_string();
        assert!(e.contains("{{NOPE}}"), "{e}");
        let e = fill("x {{OPEN", &[]).unwrap_err().to_string();
        assert!(e.contains("unclosed"), "{e}");
    }
}
