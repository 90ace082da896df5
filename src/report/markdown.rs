//! Markdown for the reports' README.md files: a document built from headings, paragraphs,
//! lists, images and tables, so that a report's text reads as its sections and no writer
//! spells out table rules or blank lines by hand.

use std::fmt::Display;

/// A Markdown document.
#[derive(Debug, Default)]
pub struct Doc {
    text: String,
}

impl Doc {
    /// An empty document.
    pub fn new() -> Self {
        Doc::default()
    }
    /// A heading of `level` (1: `#`), followed by a blank line.
    pub fn heading(&mut self, level: usize, title: impl Display) -> &mut Self {
        self.text += &format!("{} {title}\n\n", "#".repeat(level));
        self
    }
    /// A paragraph, followed by a blank line.
    pub fn paragraph(&mut self, text: impl Display) -> &mut Self {
        self.text += &format!("{text}\n\n");
        self
    }
    /// One line, with no blank line after it (a list item, or text that continues).
    pub fn line(&mut self, text: impl Display) -> &mut Self {
        self.text += &format!("{text}\n");
        self
    }
    /// A list item `- text`.
    pub fn bullet(&mut self, text: impl Display) -> &mut Self {
        self.text += &format!("- {text}\n");
        self
    }
    /// A list: one item `- text` per entry, then a blank line (nothing for no entries).
    pub fn list<S: Display>(&mut self, items: impl IntoIterator<Item = S>) -> &mut Self {
        let before = self.text.len();
        for item in items {
            self.bullet(item);
        }
        if self.text.len() > before {
            self.blank();
        }
        self
    }
    /// A blank line (ends a list).
    pub fn blank(&mut self) -> &mut Self {
        self.text.push('\n');
        self
    }
    /// An image `![alt](file)` as a paragraph.
    pub fn image(&mut self, alt: &str, file: &str) -> &mut Self {
        self.paragraph(format!("![{alt}]({file})"))
    }
    /// A table, followed by a blank line.
    pub fn table(&mut self, table: &Table) -> &mut Self {
        self.text += &table.render();
        self.text.push('\n');
        self
    }
    /// The text so far.
    pub fn as_str(&self) -> &str {
        &self.text
    }
    /// The document's text.
    pub fn finish(self) -> String {
        self.text
    }
}

/// A Markdown table: a header row and rows of cells.
#[derive(Debug, Clone)]
pub struct Table {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Table {
    /// A table with these column titles.
    pub fn new<S: Display>(header: impl IntoIterator<Item = S>) -> Self {
        Table {
            header: header.into_iter().map(|h| h.to_string()).collect(),
            rows: Vec::new(),
        }
    }
    /// Add a row; it must have one cell per column.
    pub fn row<S: Display>(&mut self, cells: impl IntoIterator<Item = S>) -> &mut Self {
        let cells: Vec<String> = cells.into_iter().map(|c| c.to_string()).collect();
        assert_eq!(
            cells.len(),
            self.header.len(),
            "a table row needs one cell per column: {cells:?}"
        );
        self.rows.push(cells);
        self
    }
    /// Whether the table has no rows.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }
    /// The table's text: `| a | b |`, the rule `|---|---|`, one line per row.
    pub fn render(&self) -> String {
        let line = |cells: &[String]| format!("| {} |\n", cells.join(" | "));
        let mut s = line(&self.header);
        s += &format!("|{}\n", "---|".repeat(self.header.len()));
        for r in &self.rows {
            s += &line(r);
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_table_renders_its_rule_and_rows() {
        let mut t = Table::new(["level", "error"]);
        t.row(["0", "1.0e-2"]).row(["1", "2.5e-3"]);
        let mut d = Doc::new();
        d.heading(2, "Errors").table(&t).bullet("fitted");
        assert_eq!(
            d.finish(),
            "## Errors\n\n| level | error |\n|---|---|\n| 0 | 1.0e-2 |\n| 1 | 2.5e-3 |\n\n- fitted\n"
        );
    }

    #[test]
    fn a_list_ends_with_a_blank_line_and_an_empty_one_writes_nothing() {
        let mut d = Doc::new();
        d.list(Vec::<String>::new()).list(["a", "b"]).line("Data.");
        assert_eq!(d.finish(), "- a\n- b\n\nData.\n");
    }

    #[test]
    fn empty_cells_keep_their_column() {
        let mut t = Table::new(["a", "b", "c"]);
        t.row(["1", "", "3"]);
        assert_eq!(t.render(), "| a | b | c |\n|---|---|---|\n| 1 |  | 3 |\n");
    }
}

/// The items joined by `sep`, or `none` where there are none.
pub fn listed(items: &[String], sep: &str, none: &str) -> String {
    if items.is_empty() {
        none.to_string()
    } else {
        items.join(sep)
    }
}

/// Where docs/results.md links to the reports and to the rate rules (relative to docs/).
pub const DOCS_REPORTS: &str = "../reports";
/// Where README.md links to the reports (relative to the repository's root).
pub const README_REPORTS: &str = "reports";
