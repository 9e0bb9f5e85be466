//! The one-line editor of the filter, search and palette prompts, with history and
//! completion, and the prompt bar that owns it.

use crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use ratatui::Frame;
use ratatui::layout::{Position, Rect};
use ratatui::text::{Line, Span};
use ratatui::widgets::Paragraph;

/// What a prompt is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PromptKind {
    /// Editing the filter.
    Filter,
    /// Typing a search.
    Search,
    /// The command palette.
    Palette,
    /// Finding an object in the Objects pane (the rows follow each key).
    Find,
    /// An entry of the Transmit pane, in the list file's JSON.
    Transmit,
}

impl PromptKind {
    /// The prompt's leading text.
    pub fn lead(self) -> &'static str {
        match self {
            PromptKind::Filter => "filter: ",
            PromptKind::Search => "search: ",
            PromptKind::Palette => ":",
            PromptKind::Find => "find object: ",
            PromptKind::Transmit => "transmit entry: ",
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

    /// Completes the word under the cursor from `candidates` (case ignored; the word is
    /// replaced by the candidate's spelling): a unique match is completed; several matches
    /// are completed to their common prefix and returned for display.
    pub fn complete(&mut self, candidates: &[&str]) -> Vec<String> {
        let b = self.byte(self.cursor);
        let start = self.text[..b].rfind(' ').map(|i| i + 1).unwrap_or(0);
        let word = self.text[start..b].to_lowercase();
        let hits: Vec<&str> = candidates
            .iter()
            .copied()
            .filter(|c| c.to_lowercase().starts_with(&word))
            .collect();
        let Some(first) = hits.first() else {
            return Vec::new();
        };
        let mut common: Vec<char> = first.chars().collect();
        for h in &hits[1..] {
            let same = common
                .iter()
                .zip(h.chars())
                .take_while(|(a, b)| a.to_lowercase().eq(b.to_lowercase()))
                .count();
            common.truncate(same);
        }
        let mut replaced: String = common.iter().collect();
        if hits.len() == 1 {
            replaced.push(' ');
        }
        if replaced.chars().count() >= word.chars().count() {
            self.text.replace_range(start..b, &replaced);
            self.cursor = self.text[..start].chars().count() + replaced.chars().count();
        }
        if hits.len() > 1 {
            hits.iter().map(|s| s.to_string()).collect()
        } else {
            Vec::new()
        }
    }
}

/// What a key did to the prompt bar.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Edit {
    /// The line changed, or nothing happened.
    Editing,
    /// The prompt was closed without a line.
    Cancelled,
    /// `enter`: the line (trimmed) is to be run.
    Submit(PromptKind, String),
    /// `tab` in the palette: complete the word under the cursor.
    Complete,
}

/// The prompt line at the bottom: the line being edited, if any, and the history the
/// prompts share.
#[derive(Default)]
pub struct PromptBar {
    /// The line being edited.
    pub editing: Option<Prompt>,
    /// Lines entered, newest last.
    pub history: Vec<String>,
}

impl PromptBar {
    /// Opens a `kind` prompt holding `text`.
    pub fn open(&mut self, kind: PromptKind, text: &str) {
        self.editing = Some(Prompt::new(kind, text));
    }

    /// Opens a `kind` prompt holding `text`, the cursor at character `cursor` (at most the
    /// end of the text).
    pub fn open_at(&mut self, kind: PromptKind, text: &str, cursor: usize) {
        let mut p = Prompt::new(kind, text);
        p.cursor = cursor.min(p.cursor);
        self.editing = Some(p);
    }

    /// The line being edited, if any.
    pub fn editing(&self) -> Option<&Prompt> {
        self.editing.as_ref()
    }

    /// The text before the cursor of the line being edited (empty when none is).
    pub fn before_cursor(&self) -> String {
        self.editing
            .as_ref()
            .map(|p| p.text.chars().take(p.cursor).collect())
            .unwrap_or_default()
    }

    /// Handles a key while a prompt is open; `enter` keeps the line in the history.
    pub fn key(&mut self, ev: KeyEvent) -> Edit {
        let Some(p) = self.editing.as_mut() else {
            return Edit::Cancelled;
        };
        let ctrl = ev.modifiers.contains(KeyModifiers::CONTROL);
        match ev.code {
            KeyCode::Esc => self.editing = None,
            KeyCode::Char('c') if ctrl => self.editing = None,
            KeyCode::Enter => {
                let kind = p.kind;
                let text = p.text.trim().to_string();
                self.editing = None;
                if !text.is_empty() && self.history.last() != Some(&text) {
                    self.history.push(text.clone());
                }
                return Edit::Submit(kind, text);
            }
            KeyCode::Char('a') if ctrl => p.jump(false),
            KeyCode::Char('e') if ctrl => p.jump(true),
            KeyCode::Char('u') if ctrl => *p = Prompt::new(p.kind, ""),
            KeyCode::Char(c) => p.insert(c),
            KeyCode::Backspace => p.backspace(),
            KeyCode::Delete => p.delete(),
            KeyCode::Left => p.move_by(-1),
            KeyCode::Right => p.move_by(1),
            KeyCode::Home => p.jump(false),
            KeyCode::End => p.jump(true),
            KeyCode::Up => p.history(&self.history, true),
            KeyCode::Down => p.history(&self.history, false),
            KeyCode::Tab if p.kind == PromptKind::Palette => return Edit::Complete,
            _ => {}
        }
        if self.editing.is_some() {
            Edit::Editing
        } else {
            Edit::Cancelled
        }
    }

    /// Completes the word under the cursor from `candidates` (see [`Prompt::complete`]).
    pub fn complete(&mut self, candidates: &[&str]) -> Vec<String> {
        self.editing
            .as_mut()
            .map(|p| p.complete(candidates))
            .unwrap_or_default()
    }

    /// Draws the line being edited into `line`, with the cursor; false when none is.
    pub fn render(&self, f: &mut Frame, line: Rect) -> bool {
        let Some(p) = &self.editing else {
            return false;
        };
        let lead = p.kind.lead();
        f.render_widget(
            Paragraph::new(Line::from(vec![Span::raw(lead), Span::raw(p.text.clone())])),
            line,
        );
        let x = line.x + (lead.chars().count() + p.cursor) as u16;
        if x < line.x + line.width {
            f.set_cursor_position(Position::new(x, line.y));
        }
        true
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
        let mut c = Prompt::new(PromptKind::Palette, "sdo read 2 stat");
        assert!(c.complete(&["Statusword", "Controlword"]).is_empty());
        assert_eq!((c.text.as_str(), c.cursor), ("sdo read 2 Statusword ", 22));
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
