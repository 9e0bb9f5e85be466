//! The one-line editor of the filter, search and palette prompts, with history and
//! completion.

/// What a prompt is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PromptKind {
    /// Editing the filter.
    Filter,
    /// Typing a search.
    Search,
    /// The command palette.
    Palette,
}

impl PromptKind {
    /// The prompt's leading text.
    pub fn lead(self) -> &'static str {
        match self {
            PromptKind::Filter => "filter: ",
            PromptKind::Search => "search: ",
            PromptKind::Palette => ":",
        }
    }
}

/// A line being edited.
#[derive(Clone, Debug)]
pub struct Prompt {
    /// What it is for.
    pub kind: PromptKind,
    /// The text.
    pub text: String,
    /// Cursor position in characters.
    pub cursor: usize,
    /// Position in the history while browsing it (`None`: editing a new line).
    browsing: Option<usize>,
}

impl Prompt {
    /// A prompt holding `text`, cursor at the end.
    pub fn new(kind: PromptKind, text: &str) -> Prompt {
        Prompt {
            kind,
            text: text.to_string(),
            cursor: text.chars().count(),
            browsing: None,
        }
    }

    fn byte(&self, at: usize) -> usize {
        self.text
            .char_indices()
            .nth(at)
            .map(|(i, _)| i)
            .unwrap_or(self.text.len())
    }

    /// Inserts a character at the cursor.
    pub fn insert(&mut self, c: char) {
        let b = self.byte(self.cursor);
        self.text.insert(b, c);
        self.cursor += 1;
    }

    /// Deletes the character before the cursor.
    pub fn backspace(&mut self) {
        if self.cursor > 0 {
            self.cursor -= 1;
            let b = self.byte(self.cursor);
            self.text.remove(b);
        }
    }

    /// Deletes the character under the cursor.
    pub fn delete(&mut self) {
        if self.cursor < self.text.chars().count() {
            let b = self.byte(self.cursor);
            self.text.remove(b);
        }
    }

    /// Moves the cursor by `d` characters.
    pub fn move_by(&mut self, d: isize) {
        let n = self.text.chars().count() as isize;
        self.cursor = (self.cursor as isize + d).clamp(0, n) as usize;
    }

    /// Moves to the start (`false`) or the end (`true`).
    pub fn jump(&mut self, end: bool) {
        self.cursor = if end { self.text.chars().count() } else { 0 };
    }

    /// Steps through `history` (newest last): `back` goes to older lines.
    pub fn history(&mut self, history: &[String], back: bool) {
        if history.is_empty() {
            return;
        }
        let next = match (self.browsing, back) {
            (None, true) => Some(history.len() - 1),
            (None, false) => None,
            (Some(i), true) => Some(i.saturating_sub(1)),
            (Some(i), false) if i + 1 < history.len() => Some(i + 1),
            (Some(_), false) => None,
        };
        self.browsing = next;
        self.text = next.map(|i| history[i].clone()).unwrap_or_default();
        self.jump(true);
    }

    /// Completes the word under the cursor from `candidates`: a unique match is completed;
    /// several matches are completed to their common prefix and returned for display.
    pub fn complete(&mut self, candidates: &[&str]) -> Vec<String> {
        let b = self.byte(self.cursor);
        let start = self.text[..b].rfind(' ').map(|i| i + 1).unwrap_or(0);
        let word = &self.text[start..b];
        let hits: Vec<&str> = candidates.iter().copied().filter(|c| c.starts_with(word)).collect();
        let Some(first) = hits.first() else {
            return Vec::new();
        };
        let mut common = first.to_string();
        for h in &hits[1..] {
            while !h.starts_with(&common) {
                common.pop();
            }
        }
        if hits.len() == 1 {
            common.push(' ');
        }
        let added = common[word.len()..].to_string();
        self.text.insert_str(b, &added);
        self.cursor += added.chars().count();
        if hits.len() > 1 {
            hits.iter().map(|s| s.to_string()).collect()
        } else {
            Vec::new()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn editing_history_and_completion() {
        let mut p = Prompt::new(PromptKind::Palette, "");
        for c in "sp".chars() {
            p.insert(c);
        }
        assert!(p.complete(&["speed", "search", "quit"]).is_empty());
        assert_eq!(p.text, "speed ");
        let mut q = Prompt::new(PromptKind::Palette, "s");
        assert_eq!(q.complete(&["seek", "search"]), vec!["seek", "search"]);
        assert_eq!(q.text, "se");
        q.backspace();
        q.move_by(-5);
        q.insert('x');
        assert_eq!((q.text.as_str(), q.cursor), ("xs", 1));
        let hist = vec!["one".to_string(), "two".to_string()];
        q.history(&hist, true);
        assert_eq!(q.text, "two");
        q.history(&hist, true);
        assert_eq!(q.text, "one");
        q.history(&hist, false);
        q.history(&hist, false);
        assert_eq!(q.text, "");
    }
}
