//! Why a filter did not parse: the column and a message, clipped for long words.

/// A filter that did not parse: 1-based column and what was wrong.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("column {column}: {message}")]
pub struct FilterError {
    /// 1-based column.
    pub column: usize,
    /// What was wrong.
    pub message: String,
}

/// Characters of a word quoted in a message, and of the filter shown either side of an
/// error's column: a filter of 16,000 words is not repeated in its error.
const QUOTE_CHARS: usize = 40;

impl FilterError {
    pub(super) fn new(column: usize, message: impl Into<String>) -> FilterError {
        FilterError {
            column,
            message: clip_words(message.into()),
        }
    }

    /// The part of `text` (the filter it was parsed from) around the error's column: at
    /// most [`QUOTE_CHARS`] characters either side, `…` where cut.
    pub fn excerpt(&self, text: &str) -> String {
        let at = self.column.saturating_sub(1);
        let from = at.saturating_sub(QUOTE_CHARS);
        let len = text.chars().count();
        let mut s: String = text.chars().skip(from).take(2 * QUOTE_CHARS).collect();
        if from > 0 {
            s.insert(0, '…');
        }
        if from + 2 * QUOTE_CHARS < len {
            s.push('…');
        }
        s
    }
}

/// `message` with each word longer than [`QUOTE_CHARS`] cut to its start, `…` and its
/// closing punctuation (a backquote, a quote).
fn clip_words(message: String) -> String {
    if !message.split(' ').any(|w| w.chars().count() > QUOTE_CHARS) {
        return message;
    }
    let clip = |w: &str| {
        if w.chars().count() <= QUOTE_CHARS {
            return w.to_string();
        }
        let mut s: String = w.chars().take(QUOTE_CHARS).collect();
        s.push('…');
        let tail: Vec<char> = w.chars().rev().take_while(|c| !c.is_alphanumeric()).take(2).collect();
        s.extend(tail.into_iter().rev());
        s
    };
    message.split(' ').map(clip).collect::<Vec<_>>().join(" ")
}
