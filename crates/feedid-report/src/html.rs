//! A self-contained HTML page built from sections: inline SVG figures,
//! tables and paragraphs, a header with facts, a compact table of contents
//! (one line, the full list one click away) after the leading sections that
//! hold the answer, and an inline print-friendly style sheet. No scripts, no external resources: the
//! file opens offline and prints as it looks.
//!
//! Every piece of text is HTML-escaped when written ([`escape_html`]); in
//! paragraphs, list items and answers a span between backticks is shown as
//! code (`<code>`). Only
//! the figures' SVG (produced by [`crate::plot`]) is inserted as markup, with
//! its `xmlns` attribute dropped (HTML puts inline `<svg>` in the SVG
//! namespace by itself) and its size made responsive.
//!
//! ```
//! use feedid_report::{Block, Figure, HtmlReport, Section};
//! let mut page = HtmlReport::new("Report <1>");
//! page.facts.push(("file".into(), "a&b.csv".into()));
//! page.sections.push(Section::new("s1", "First").with(Block::Figure(Figure::new(
//!     "fig-a",
//!     "A figure",
//!     "<svg width=\"10\" height=\"5\" viewBox=\"0 0 10 5\" xmlns=\"http://www.w3.org/2000/svg\"></svg>",
//!     "What to look at.",
//! ))));
//! let html = page.to_html();
//! assert!(html.contains("Report &lt;1&gt;") && html.contains("a&amp;b.csv"));
//! assert!(html.contains("id=\"fig-a\"") && !html.contains("http://"));
//! ```

use std::fmt::Write as _;

/// Escape `&`, `<`, `>`, `"` and `'` for HTML text and attribute values.
pub fn escape_html(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            _ => out.push(c),
        }
    }
    out
}

/// One figure: an SVG image with a title and a caption saying what to look at.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// Element id (unique in the page; used by the table of contents and checks).
    pub id: String,
    /// Short title (table of contents, caption start).
    pub title: String,
    /// The SVG document.
    pub svg: String,
    /// What the figure shows and what to look at (plain text).
    pub caption: String,
}

impl Figure {
    /// A figure.
    pub fn new(id: &str, title: &str, svg: &str, caption: &str) -> Self {
        Self {
            id: id.to_string(),
            title: title.to_string(),
            svg: svg.to_string(),
            caption: caption.to_string(),
        }
    }
}

/// A table of text cells; numeric-looking cells are right-aligned.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Table {
    /// Element id.
    pub id: String,
    /// Caption above the table (plain text).
    pub caption: String,
    /// Column headings.
    pub header: Vec<String>,
    /// Rows of cells.
    pub rows: Vec<Vec<String>>,
}

/// A piece of a section.
#[derive(Debug, Clone, PartialEq)]
pub enum Block {
    /// A paragraph of plain text.
    Paragraph(String),
    /// The answer the page gives: a paragraph set apart, with an element id
    /// (checks find it; it should be on the first screen).
    Answer {
        /// Element id.
        id: String,
        /// Plain text.
        text: String,
    },
    /// A bulleted list of plain-text items.
    List(Vec<String>),
    /// A full-width figure.
    Figure(Figure),
    /// Figures side by side (two per row on screen and paper).
    Grid(Vec<Figure>),
    /// A table.
    Table(Table),
}

/// A section with a heading, blocks and subsections.
#[derive(Debug, Clone, PartialEq)]
pub struct Section {
    /// Element id.
    pub id: String,
    /// Heading.
    pub title: String,
    /// Content.
    pub blocks: Vec<Block>,
    /// Nested sections.
    pub subsections: Vec<Section>,
    /// Shown folded (an HTML `<details>` element: the heading stays visible,
    /// the content is one click away, no script); default false.
    pub folded: bool,
}

impl Section {
    /// An empty section.
    pub fn new(id: &str, title: &str) -> Self {
        Self {
            id: id.to_string(),
            title: title.to_string(),
            blocks: Vec::new(),
            subsections: Vec::new(),
            folded: false,
        }
    }

    /// The same section shown folded (see [`Section::folded`]).
    pub fn fold(mut self) -> Self {
        self.folded = true;
        self
    }

    /// The same section with one more block.
    pub fn with(mut self, b: Block) -> Self {
        self.blocks.push(b);
        self
    }

    /// Figures of this section and its subsections, in page order.
    fn figures<'a>(&'a self, out: &mut Vec<&'a Figure>) {
        for b in &self.blocks {
            match b {
                Block::Figure(f) => out.push(f),
                Block::Grid(fs) => out.extend(fs.iter()),
                _ => {}
            }
        }
        for s in &self.subsections {
            s.figures(out);
        }
    }
}

/// A whole page.
#[derive(Debug, Clone, PartialEq)]
pub struct HtmlReport {
    /// Page title (`<title>` and `<h1>`).
    pub title: String,
    /// Key facts shown under the title (label, value).
    pub facts: Vec<(String, String)>,
    /// Paragraphs under the header, before the sections.
    pub intro: Vec<String>,
    /// The sections.
    pub sections: Vec<Section>,
    /// How many sections come before the table of contents (those holding
    /// the answer, so that it is on the first screen); default 0.
    pub lead_sections: usize,
}

const STYLE: &str = r#"
:root { --ink: #1a1a1a; --muted: #555; --rule: #d0d0d0; --accent: #0072b2; }
* { box-sizing: border-box; }
body { font-family: "DejaVu Sans", "Helvetica Neue", Arial, sans-serif; color: var(--ink);
       max-width: 1120px; margin: 0 auto; padding: 28px 32px 60px; line-height: 1.45; font-size: 15px; }
h1 { font-size: 26px; margin: 0 0 6px; }
h2 { font-size: 21px; margin: 38px 0 10px; padding-bottom: 4px; border-bottom: 2px solid var(--ink); }
h3 { font-size: 17px; margin: 28px 0 8px; }
header { border-bottom: 1px solid var(--rule); padding-bottom: 12px; }
dl.facts { display: grid; grid-template-columns: max-content 1fr; gap: 2px 18px; margin: 10px 0 0; }
dl.facts dt { color: var(--muted); }
dl.facts dd { margin: 0; font-variant-numeric: tabular-nums; }
nav.toc { background: #f6f7f9; border: 1px solid var(--rule); padding: 6px 14px; margin: 18px 0; font-size: 14px; }
nav.toc > details > summary { color: var(--ink); margin: 0; }
nav.toc ol { margin: 4px 0; padding-left: 22px; }
nav.toc > details > ol { columns: 2; column-gap: 28px; }
nav.toc > details > ol > li { break-inside: avoid; }
nav.toc li { margin: 1px 0; }
nav.toc ol ol { font-size: 13.5px; color: var(--muted); }
a { color: var(--accent); text-decoration: none; }
figure { margin: 16px 0 22px; break-inside: avoid; page-break-inside: avoid; }
figure svg { display: block; width: 100%; height: auto; max-width: 100%; border: 1px solid #e3e3e3; }
figcaption { font-size: 13.5px; color: #333; margin-top: 6px; }
figcaption b { color: var(--ink); }
.grid { display: grid; grid-template-columns: 1fr 1fr; gap: 0 20px; }
details > summary { cursor: pointer; color: var(--accent); margin: 0.5em 0; }
p.answer { border-left: 4px solid var(--accent); background: #f2f7fb; padding: 8px 12px; font-size: 16px; }
code { font-family: "DejaVu Sans Mono", Menlo, Consolas, monospace; font-size: 0.92em; background: #eef0f3; padding: 0 3px; border-radius: 3px; }
table { border-collapse: collapse; margin: 8px 0 18px; font-size: 14px; font-variant-numeric: tabular-nums; break-inside: avoid; }
caption { text-align: left; color: var(--muted); font-size: 13.5px; padding-bottom: 4px; }
th, td { padding: 4px 10px; border-bottom: 1px solid var(--rule); }
th { text-align: left; border-bottom: 2px solid var(--ink); background: #fafafa; }
td.num, th.num { text-align: right; }
td:not(.num) { white-space: nowrap; }
footer { margin-top: 40px; color: var(--muted); font-size: 12.5px; border-top: 1px solid var(--rule); padding-top: 8px; }
@media (max-width: 820px) { .grid { grid-template-columns: 1fr; } body { padding: 12px; } }
@media print {
  body { max-width: none; padding: 0; font-size: 11pt; }
  h2 { break-before: page; }
  section:first-of-type > h2 { break-before: auto; }
  a { color: inherit; }
  figure svg { border: none; }
}
"#;

/// Escaped text with each span between a pair of backticks shown as code;
/// an unpaired backtick stays as it is.
pub(crate) fn inline_text(s: &str) -> String {
    let parts: Vec<&str> = s.split('`').collect();
    let mut out = String::with_capacity(s.len() + 16);
    for (i, part) in parts.iter().enumerate() {
        if i % 2 == 1 && i + 1 < parts.len() {
            let _ = write!(out, "<code>{}</code>", escape_html(part));
        } else {
            if i % 2 == 1 {
                // the last backtick has no partner
                out.push('`');
            }
            out.push_str(&escape_html(part));
        }
    }
    out
}

/// Whether a cell reads as a number (right-aligned).
fn numeric(s: &str) -> bool {
    let t = s.trim().trim_end_matches('%').trim();
    !t.is_empty()
        && (t == "–"
            || t.chars()
                .all(|c| c.is_ascii_digit() || matches!(c, '.' | '-' | '+' | 'e' | '−' | ' ')))
}

/// The SVG with its opening tag rewritten for inline, responsive use.
fn inline_svg(svg: &str, label: &str) -> String {
    let svg = svg.trim_start();
    let Some(end) = svg.find('>') else {
        return String::new();
    };
    if !svg.starts_with("<svg") {
        return String::new();
    }
    let tag = &svg[..end];
    let attr = |name: &str| -> Option<String> {
        let key = format!(" {name}=\"");
        let i = tag.find(&key)? + key.len();
        let j = tag[i..].find('"')? + i;
        Some(tag[i..j].to_string())
    };
    let w = attr("width").unwrap_or_else(|| "800".into());
    let h = attr("height").unwrap_or_else(|| "400".into());
    let vb = attr("viewBox").unwrap_or_else(|| format!("0 0 {w} {h}"));
    let mut extra = String::new();
    if let Some(ff) = attr("font-family") {
        let _ = write!(extra, " font-family=\"{}\"", escape_html(&ff));
    }
    format!(
        "<svg viewBox=\"{}\" width=\"{}\" height=\"{}\" role=\"img\" aria-label=\"{}\"{extra}>{}",
        escape_html(&vb),
        escape_html(&w),
        escape_html(&h),
        escape_html(label),
        &svg[end + 1..]
    )
}

impl HtmlReport {
    /// An empty page.
    pub fn new(title: &str) -> Self {
        Self {
            title: title.to_string(),
            facts: Vec::new(),
            intro: Vec::new(),
            sections: Vec::new(),
            lead_sections: 0,
        }
    }

    /// Ids of every figure, in page order.
    pub fn figure_ids(&self) -> Vec<String> {
        let mut figs = Vec::new();
        for s in &self.sections {
            s.figures(&mut figs);
        }
        figs.into_iter().map(|f| f.id.clone()).collect()
    }

    /// The complete HTML document.
    pub fn to_html(&self) -> String {
        let mut figs = Vec::new();
        for s in &self.sections {
            s.figures(&mut figs);
        }
        let number = |id: &str| figs.iter().position(|f| f.id == id).map_or(0, |i| i + 1);
        let mut h = String::with_capacity(1 << 16);
        let _ = write!(
            h,
            "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
             <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
             <title>{}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n<header>\n<h1>{}</h1>\n",
            escape_html(&self.title),
            escape_html(&self.title)
        );
        if !self.facts.is_empty() {
            h.push_str("<dl class=\"facts\">\n");
            for (k, v) in &self.facts {
                let _ = writeln!(h, "<dt>{}</dt><dd>{}</dd>", escape_html(k), escape_html(v));
            }
            h.push_str("</dl>\n");
        }
        h.push_str("</header>\n");
        for p in &self.intro {
            let _ = writeln!(h, "<p>{}</p>", inline_text(p));
        }
        let lead = self.lead_sections.min(self.sections.len());
        h.push_str("<main>\n");
        for s in &self.sections[..lead] {
            write_section(&mut h, s, 2, &number);
        }
        // the contents in one line (the sections), every figure one click away
        let _ = write!(
            h,
            "<nav class=\"toc\" id=\"contents\">\n<details class=\"toc-list\"><summary><b>Contents</b> ({} figure{}, \
             click for the full list):",
            figs.len(),
            if figs.len() == 1 { "" } else { "s" }
        );
        for (i, s) in self.sections.iter().enumerate() {
            let _ = write!(
                h,
                "{} <a href=\"#{}\">{}</a>",
                if i == 0 { "" } else { " ·" },
                escape_html(&s.id),
                escape_html(&s.title)
            );
        }
        h.push_str("</summary>\n<ol>\n");
        for s in &self.sections {
            toc_entry(&mut h, s, &number);
        }
        h.push_str("</ol>\n</details>\n</nav>\n");
        for s in &self.sections[lead..] {
            write_section(&mut h, s, 2, &number);
        }
        let _ = write!(
            h,
            "</main>\n<footer>Generated by feedid {} — a self-contained file: no scripts, \
             no network; figures are inline SVG.</footer>\n</body>\n</html>\n",
            env!("CARGO_PKG_VERSION")
        );
        h
    }
}

fn toc_entry(h: &mut String, s: &Section, number: &dyn Fn(&str) -> usize) {
    let _ = write!(
        h,
        "<li><a href=\"#{}\">{}</a>",
        escape_html(&s.id),
        escape_html(&s.title)
    );
    if s.folded {
        // folded: one line, the figures are one click away in the section
        let mut figs = Vec::new();
        s.figures(&mut figs);
        let _ = writeln!(h, " (folded, {} figures)</li>", figs.len());
        return;
    }
    let mut own = Vec::new();
    for b in &s.blocks {
        match b {
            Block::Figure(f) => own.push(f),
            Block::Grid(fs) => own.extend(fs.iter()),
            _ => {}
        }
    }
    if !own.is_empty() || !s.subsections.is_empty() {
        h.push_str("\n<ol>\n");
        for f in own {
            let _ = writeln!(
                h,
                "<li><a href=\"#{}\">Figure {}: {}</a></li>",
                escape_html(&f.id),
                number(&f.id),
                escape_html(&f.title)
            );
        }
        for sub in &s.subsections {
            toc_entry(h, sub, number);
        }
        h.push_str("</ol>\n");
    }
    h.push_str("</li>\n");
}

fn write_figure(h: &mut String, f: &Figure, number: &dyn Fn(&str) -> usize) {
    let _ = write!(
        h,
        "<figure id=\"{}\">\n{}\n<figcaption><b>Figure {}. {}.</b> {}</figcaption>\n</figure>\n",
        escape_html(&f.id),
        inline_svg(&f.svg, &f.title),
        number(&f.id),
        escape_html(f.title.trim_end_matches('.')),
        escape_html(&f.caption)
    );
}

fn write_section(h: &mut String, s: &Section, level: usize, number: &dyn Fn(&str) -> usize) {
    let lv = level.min(6);
    let _ = writeln!(
        h,
        "<section id=\"{}\">\n<h{lv}>{}</h{lv}>",
        escape_html(&s.id),
        escape_html(&s.title)
    );
    if s.folded {
        let mut figs = Vec::new();
        s.figures(&mut figs);
        let _ = writeln!(
            h,
            "<details><summary>{} — {} figure{}, click to show</summary>",
            escape_html(&s.title),
            figs.len(),
            if figs.len() == 1 { "" } else { "s" }
        );
    }
    for b in &s.blocks {
        match b {
            Block::Paragraph(p) => {
                let _ = writeln!(h, "<p>{}</p>", inline_text(p));
            }
            Block::Answer { id, text } => {
                let _ = writeln!(
                    h,
                    "<p class=\"answer\" id=\"{}\">{}</p>",
                    escape_html(id),
                    inline_text(text)
                );
            }
            Block::List(items) => {
                h.push_str("<ul>\n");
                for i in items {
                    let _ = writeln!(h, "<li>{}</li>", inline_text(i));
                }
                h.push_str("</ul>\n");
            }
            Block::Figure(f) => write_figure(h, f, number),
            Block::Grid(fs) => {
                h.push_str("<div class=\"grid\">\n");
                for f in fs {
                    write_figure(h, f, number);
                }
                h.push_str("</div>\n");
            }
            Block::Table(t) => {
                let _ = writeln!(h, "<table id=\"{}\">", escape_html(&t.id));
                if !t.caption.is_empty() {
                    let _ = writeln!(h, "<caption>{}</caption>", escape_html(&t.caption));
                }
                h.push_str("<thead><tr>");
                for (j, c) in t.header.iter().enumerate() {
                    let num = t.rows.iter().any(|r| r.get(j).is_some_and(|v| numeric(v)));
                    let _ = write!(
                        h,
                        "<th{}>{}</th>",
                        if num && j > 0 { " class=\"num\"" } else { "" },
                        escape_html(c)
                    );
                }
                h.push_str("</tr></thead>\n<tbody>\n");
                for r in &t.rows {
                    h.push_str("<tr>");
                    for (j, c) in r.iter().enumerate() {
                        let _ = write!(
                            h,
                            "<td{}>{}</td>",
                            if numeric(c) && j > 0 {
                                " class=\"num\""
                            } else {
                                ""
                            },
                            escape_html(c)
                        );
                    }
                    h.push_str("</tr>\n");
                }
                h.push_str("</tbody>\n</table>\n");
            }
        }
    }
    for sub in &s.subsections {
        write_section(h, sub, level + 1, number);
    }
    if s.folded {
        h.push_str("</details>\n");
    }
    h.push_str("</section>\n");
}

#[cfg(test)]
mod tests {
    use super::*;

    fn svg() -> String {
        "<svg width=\"900\" height=\"420\" viewBox=\"0 0 900 420\" xmlns=\"http://www.w3.org/2000/svg\">\n<rect/></svg>\n".into()
    }

    fn page() -> HtmlReport {
        let mut p = HtmlReport::new("feedid report: <script>alert(1)</script>.csv");
        p.facts.push(("file".into(), "x\"y'&.csv".into()));
        p.intro.push("Read me & <b>this</b>".into());
        let mut s = Section::new("sec-a", "Section <A>")
            .with(Block::Paragraph("p1".into()))
            .with(Block::Figure(Figure::new("f1", "First", &svg(), "look")))
            .with(Block::Table(Table {
                id: "t1".into(),
                caption: "numbers".into(),
                header: vec!["name".into(), "rms [µm]".into()],
                rows: vec![vec!["<m>".into(), "1.25".into()]],
            }));
        s.subsections
            .push(Section::new("sec-b", "Sub").with(Block::Grid(vec![
                Figure::new("f2", "Second", &svg(), "c2"),
                Figure::new("f3", "Third", &svg(), "c3"),
            ])));
        p.sections.push(s);
        p
    }

    #[test]
    fn user_strings_are_escaped_everywhere() {
        let html = page().to_html();
        assert!(!html.contains("<script"), "no script element at all");
        assert!(html.contains("&lt;script&gt;alert(1)&lt;/script&gt;.csv"));
        assert!(html.contains("x&quot;y&#39;&amp;.csv"));
        assert!(html.contains("Read me &amp; &lt;b&gt;this&lt;/b&gt;"));
        assert!(html.contains("<td>&lt;m&gt;</td><td class=\"num\">1.25</td>"));
        assert!(html.contains("Section &lt;A&gt;"));
    }

    #[test]
    fn figures_are_numbered_inline_and_listed_in_the_contents() {
        let p = page();
        assert_eq!(p.figure_ids(), vec!["f1", "f2", "f3"]);
        let html = p.to_html();
        for (k, id) in ["f1", "f2", "f3"].iter().enumerate() {
            assert!(html.contains(&format!("<figure id=\"{id}\">")));
            assert!(html.contains(&format!("<a href=\"#{id}\">Figure {}:", k + 1)));
        }
        assert_eq!(html.matches("<svg viewBox=\"0 0 900 420\"").count(), 3);
        assert!(!html.contains("xmlns"), "namespace attribute dropped");
        assert!(!html.contains("http://") && !html.contains("https://"));
        assert!(html.contains("<h3>Sub</h3>"));
        assert!(html.contains("<div class=\"grid\">"));
    }

    #[test]
    fn backtick_spans_are_code_and_escaped() {
        assert_eq!(
            inline_text("run `a <b>` now"),
            "run <code>a &lt;b&gt;</code> now"
        );
        assert_eq!(
            inline_text("`x` and `y`"),
            "<code>x</code> and <code>y</code>"
        );
        assert_eq!(inline_text("one ` left"), "one ` left");
        assert_eq!(inline_text("`a` b ` c"), "<code>a</code> b ` c");
        let mut p = page();
        p.sections[0].blocks.push(Block::Answer {
            id: "the-answer".into(),
            text: "use `feedid x`".into(),
        });
        let html = p.to_html();
        assert!(
            html.contains("<p class=\"answer\" id=\"the-answer\">use <code>feedid x</code></p>")
        );
    }

    #[test]
    fn lead_sections_come_before_the_one_line_contents() {
        let mut p = page();
        p.sections.push(Section::new("sec-c", "Later"));
        let html = p.to_html();
        let toc = html.find("<nav class=\"toc\" id=\"contents\">").unwrap();
        assert!(toc < html.find("<section id=\"sec-a\">").unwrap());
        p.lead_sections = 1;
        let html = p.to_html();
        let toc = html.find("<nav class=\"toc\" id=\"contents\">").unwrap();
        assert!(html.find("<section id=\"sec-a\">").unwrap() < toc);
        assert!(toc < html.find("<section id=\"sec-c\">").unwrap());
        // one line of section links; the figures one click away
        assert!(html.contains(
            "<summary><b>Contents</b> (3 figures, click for the full list): \
             <a href=\"#sec-a\">Section &lt;A&gt;</a> · <a href=\"#sec-c\">Later</a></summary>"
        ));
        // every section once in the page
        assert_eq!(html.matches("<section id=\"sec-a\">").count(), 1);
    }

    #[test]
    fn numeric_cells_are_recognised() {
        assert!(numeric("1.25") && numeric("-3e-5") && numeric("99.1 %") && numeric("–"));
        assert!(!numeric("paper") && !numeric("") && !numeric("8,8,1 arx"));
    }

    #[test]
    fn escape_html_handles_every_special_character() {
        assert_eq!(
            escape_html("<a href='x'>&\"</a>"),
            "&lt;a href=&#39;x&#39;&gt;&amp;&quot;&lt;/a&gt;"
        );
        assert_eq!(escape_html("µm – ok"), "µm – ok");
    }
}
