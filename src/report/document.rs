//! A small document model rendered to both Markdown and HTML, so `report.md` and
//! `report.html` hold the same content without a Markdown parser.

use std::fmt::Write;

/// A run of inline content.
#[derive(Debug, Clone)]
pub enum Inline {
    Text(String),
    /// Monospace (paths, flags, file names).
    Code(String),
    Bold(String),
    /// A link to a file in the report directory: (text, target).
    Link(String, String),
}

/// A block of the document.
#[derive(Debug, Clone)]
pub enum Block {
    Heading(u8, String),
    Paragraph(Vec<Inline>),
    /// A table: header cells and rows; the first column is left-aligned, the others too
    /// unless `numeric` (then right-aligned).
    Table {
        header: Vec<String>,
        rows: Vec<Vec<String>>,
        numeric: bool,
    },
    /// An image in the report directory: (alt text, file name).
    Image(String, String),
    List(Vec<Vec<Inline>>),
}

pub fn text(s: impl Into<String>) -> Inline {
    Inline::Text(s.into())
}

pub fn code(s: impl Into<String>) -> Inline {
    Inline::Code(s.into())
}

pub fn bold(s: impl Into<String>) -> Inline {
    Inline::Bold(s.into())
}

pub fn link(label: impl Into<String>, target: impl Into<String>) -> Inline {
    Inline::Link(label.into(), target.into())
}

pub fn para(inlines: Vec<Inline>) -> Block {
    Block::Paragraph(inlines)
}

#[derive(Debug, Clone, Default)]
pub struct Document {
    pub title: String,
    pub blocks: Vec<Block>,
}

impl Document {
    pub fn push(&mut self, block: Block) {
        self.blocks.push(block);
    }

    /// The document as CommonMark (GitHub tables).
    pub fn markdown(&self) -> String {
        let mut s = format!("# {}\n", md_text(&self.title));
        for block in &self.blocks {
            s.push('\n');
            match block {
                Block::Heading(level, t) => {
                    let _ = writeln!(s, "{} {}", "#".repeat(*level as usize), md_text(t));
                }
                Block::Paragraph(inl) => {
                    let _ = writeln!(s, "{}", md_inlines(inl));
                }
                Block::Table {
                    header,
                    rows,
                    numeric,
                } => {
                    let cell = |c: &String| md_text(c).replace('|', "\\|");
                    let line = |cells: &[String]| {
                        format!(
                            "| {} |",
                            cells.iter().map(cell).collect::<Vec<_>>().join(" | ")
                        )
                    };
                    let _ = writeln!(s, "{}", line(header));
                    let align: Vec<&str> = (0..header.len())
                        .map(|i| if i == 0 || !numeric { ":---" } else { "---:" })
                        .collect();
                    let _ = writeln!(s, "|{}|", align.join("|"));
                    for r in rows {
                        let _ = writeln!(s, "{}", line(r));
                    }
                }
                Block::Image(alt, src) => {
                    let _ = writeln!(s, "![{}]({})", md_text(alt), src);
                }
                Block::List(items) => {
                    for item in items {
                        let _ = writeln!(s, "- {}", md_inlines(item));
                    }
                }
            }
        }
        s
    }

    /// The document as a standalone, well-formed HTML page (no scripts; images by relative
    /// path).
    pub fn html(&self) -> String {
        let mut s = String::from("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n");
        s += "<meta charset=\"utf-8\"/>\n";
        let _ = writeln!(s, "<title>{}</title>", esc(&self.title));
        s += "<style>\n\
              body { font-family: sans-serif; max-width: 1100px; margin: 2em auto; padding: 0 1em; color: #222; }\n\
              table { border-collapse: collapse; margin: 1em 0; }\n\
              th, td { border: 1px solid #bbb; padding: 0.25em 0.6em; }\n\
              th { background: #eee; }\n\
              td.num, th.num { text-align: right; font-variant-numeric: tabular-nums; }\n\
              img { max-width: 100%; border: 1px solid #ddd; margin: 0.5em 0; }\n\
              code { background: #f3f3f3; padding: 0 0.2em; }\n\
              </style>\n</head>\n<body>\n";
        let _ = writeln!(s, "<h1>{}</h1>", esc(&self.title));
        for block in &self.blocks {
            match block {
                Block::Heading(level, t) => {
                    let l = (*level).clamp(1, 6);
                    let _ = writeln!(s, "<h{l}>{}</h{l}>", esc(t));
                }
                Block::Paragraph(inl) => {
                    let _ = writeln!(s, "<p>{}</p>", html_inlines(inl));
                }
                Block::Table {
                    header,
                    rows,
                    numeric,
                } => {
                    let class = |i: usize| {
                        if i == 0 || !numeric {
                            ""
                        } else {
                            " class=\"num\""
                        }
                    };
                    s += "<table>\n<thead><tr>";
                    for (i, h) in header.iter().enumerate() {
                        let _ = write!(s, "<th{}>{}</th>", class(i), esc(h));
                    }
                    s += "</tr></thead>\n<tbody>\n";
                    for r in rows {
                        s += "<tr>";
                        for (i, c) in r.iter().enumerate() {
                            let _ = write!(s, "<td{}>{}</td>", class(i), esc(c));
                        }
                        s += "</tr>\n";
                    }
                    s += "</tbody>\n</table>\n";
                }
                Block::Image(alt, src) => {
                    let _ = writeln!(
                        s,
                        "<p><a href=\"{0}\"><img src=\"{0}\" alt=\"{1}\"/></a></p>",
                        esc(src),
                        esc(alt)
                    );
                }
                Block::List(items) => {
                    s += "<ul>\n";
                    for item in items {
                        let _ = writeln!(s, "<li>{}</li>", html_inlines(item));
                    }
                    s += "</ul>\n";
                }
            }
        }
        s += "</body>\n</html>\n";
        s
    }
}

/// Escapes the characters that Markdown could read as markup in running text.
fn md_text(t: &str) -> String {
    let chars: Vec<char> = t.chars().collect();
    let mut s = String::with_capacity(t.len());
    for (i, &c) in chars.iter().enumerate() {
        // `_` inside a word (t_2, small_drum, T̄_hot) is never emphasis; next to a space or
        // punctuation it can be.
        let word = |j: Option<usize>| {
            j.and_then(|j| chars.get(j))
                .is_some_and(|c| !c.is_whitespace() && !c.is_ascii_punctuation())
        };
        let boundary_underscore = c == '_' && !(word(i.checked_sub(1)) && word(Some(i + 1)));
        if matches!(c, '\\' | '*' | '[' | ']' | '<' | '>' | '`') || boundary_underscore {
            s.push('\\');
        }
        s.push(c);
    }
    s
}

fn md_code(t: &str) -> String {
    // A code span delimited by more backticks than the longest run inside it.
    let longest = t.split(|c| c != '`').map(str::len).max().unwrap_or(0);
    let fence = "`".repeat(longest + 1);
    let pad = if t.starts_with('`') || t.ends_with('`') {
        " "
    } else {
        ""
    };
    format!("{fence}{pad}{t}{pad}{fence}")
}

fn md_inlines(inl: &[Inline]) -> String {
    inl.iter()
        .map(|i| match i {
            Inline::Text(t) => md_text(t),
            Inline::Code(t) => md_code(t),
            Inline::Bold(t) => format!("**{}**", md_text(t)),
            Inline::Link(label, target) => format!("[{}]({})", md_text(label), target),
        })
        .collect()
}

pub fn esc(t: &str) -> String {
    let mut s = String::with_capacity(t.len());
    for c in t.chars() {
        match c {
            '&' => s.push_str("&amp;"),
            '<' => s.push_str("&lt;"),
            '>' => s.push_str("&gt;"),
            '"' => s.push_str("&quot;"),
            _ => s.push(c),
        }
    }
    s
}

fn html_inlines(inl: &[Inline]) -> String {
    inl.iter()
        .map(|i| match i {
            Inline::Text(t) => esc(t),
            Inline::Code(t) => format!("<code>{}</code>", esc(t)),
            Inline::Bold(t) => format!("<strong>{}</strong>", esc(t)),
            Inline::Link(label, target) => {
                format!("<a href=\"{}\">{}</a>", esc(target), esc(label))
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markdown_and_html_hold_the_same_blocks() {
        let mut d = Document {
            title: "a <b> & c".into(),
            ..Default::default()
        };
        d.push(Block::Heading(2, "Errors".into()));
        d.push(para(vec![text("see "), code("a`b"), link("x", "x.svg")]));
        d.push(Block::Table {
            header: vec!["".into(), "t_2".into()],
            rows: vec![vec!["eps | abs".into(), "0.1".into()]],
            numeric: true,
        });
        d.push(Block::Image("plot".into(), "x.svg".into()));
        let md = d.markdown();
        assert!(md.starts_with("# a \\<b\\> & c\n"), "{md}");
        assert!(md.contains("``a`b``"), "{md}");
        assert!(md.contains("[x](x.svg)"));
        assert!(md.contains("| eps \\| abs | 0.1 |"), "{md}");
        assert!(md.contains("|:---|---:|"), "{md}");
        assert!(md.contains("![plot](x.svg)"));
        let html = d.html();
        assert!(html.contains("<title>a &lt;b&gt; &amp; c</title>"));
        assert!(html.contains("<img src=\"x.svg\" alt=\"plot\"/>"));
        assert!(html.contains("<code>a`b</code>"));
    }
}
