//! The line of an XML node in time independent of where it lies (issue 56): roxmltree's
//! `text_pos_at` counts the newlines from the start of the text on every call, so a file of
//! n elements, each named by its line, took time growing with n² (a hand of 80,000 fixed
//! links, 8.8 MB, ran for minutes). A reader that names lines enters the document's newline
//! table once with [`Lines::enter`]; [`line_of`] then finds a line by binary search.

use std::cell::RefCell;

thread_local! {
    /// The tables entered on this thread and not yet left: (text's address, length, the byte
    /// offsets of its newlines).
    static TABLES: RefCell<Vec<(usize, usize, Vec<usize>)>> = const { RefCell::new(Vec::new()) };
}

/// A document's newline table, entered for as long as this value lives.
pub(crate) struct Lines(());

impl Lines {
    /// Enters the newline table of `text`, which must outlive the returned value's use (the
    /// document parsed from it is borrowed from it, so it does).
    pub(crate) fn enter(text: &str) -> Lines {
        let newlines = text
            .bytes()
            .enumerate()
            .filter(|&(_, b)| b == b'\n')
            .map(|(i, _)| i)
            .collect();
        TABLES.with(|t| {
            t.borrow_mut()
                .push((text.as_ptr() as usize, text.len(), newlines))
        });
        Lines(())
    }
}

impl Drop for Lines {
    fn drop(&mut self) {
        TABLES.with(|t| {
            t.borrow_mut().pop();
        });
    }
}

/// The line (from 1) where `node` starts, as roxmltree's `text_pos_at` gives it: by the
/// entered table of its document, or by counting where none was entered.
pub(crate) fn line_of(node: roxmltree::Node) -> u32 {
    let text = node.document().input_text();
    let pos = node.range().start.min(text.len());
    let key = (text.as_ptr() as usize, text.len());
    TABLES
        .with(|t| {
            t.borrow()
                .iter()
                .rev()
                .find(|(at, len, _)| (*at, *len) == key)
                .map(|(_, _, newlines)| 1 + newlines.partition_point(|&o| o < pos) as u32)
        })
        .unwrap_or_else(|| node.document().text_pos_at(pos).row)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_from_the_table_are_roxmltrees() {
        let text = "<a>\n  <b/>\r\n<c>\n\n<d x=\"1\n2\"/></c>\n<e/></a>\n";
        let doc = roxmltree::Document::parse(text).unwrap();
        let elements = || doc.descendants().filter(|n| n.is_element());
        let counted: Vec<u32> = elements().map(line_of).collect();
        let _lines = Lines::enter(text);
        let indexed: Vec<u32> = elements().map(line_of).collect();
        assert_eq!(indexed, counted);
        assert_eq!(indexed, vec![1, 2, 3, 5, 7]);
    }
}
