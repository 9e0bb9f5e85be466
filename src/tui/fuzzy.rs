//! Fuzzy matching for pickers: every word typed must appear in the candidate's text with
//! its letters in order; matches at word starts and in runs score higher.

/// The score of `query` against `text` (higher is better); None when a word of the query
/// does not match. An empty query matches everything with score 0. Case is ignored.
pub fn score(query: &str, text: &str) -> Option<i64> {
    let hay: Vec<char> = text.to_lowercase().chars().collect();
    let mut total = 0;
    for word in query.split_whitespace() {
        total += word_score(&word.to_lowercase().chars().collect::<Vec<_>>(), &hay)?;
    }
    Some(total)
}

/// The best score of one word: the letters in order, from each possible first letter.
fn word_score(word: &[char], hay: &[char]) -> Option<i64> {
    let first = *word.first()?;
    (0..hay.len())
        .filter(|&i| hay[i] == first)
        .filter_map(|i| from(word, hay, i))
        .max()
}

/// Greedy match of `word` in `hay` starting at `start`: +10 per letter, +8 per letter right
/// after the previous one, +6 for a letter at a word start, minus the letters skipped.
fn from(word: &[char], hay: &[char], start: usize) -> Option<i64> {
    let mut at = start;
    let mut score = 0i64;
    let mut prev: Option<usize> = None;
    for &c in word {
        while at < hay.len() && hay[at] != c {
            at += 1;
        }
        if at == hay.len() {
            return None;
        }
        score += 10;
        match prev {
            Some(p) if p + 1 == at => score += 8,
            Some(p) => score -= (at - p - 1) as i64,
            None => {}
        }
        if at == 0 || !hay[at - 1].is_alphanumeric() {
            score += 6;
        }
        prev = Some(at);
        at += 1;
    }
    Some(score)
}

#[cfg(test)]
mod tests {
    use super::score;

    #[test]
    fn words_match_in_any_order_letters_in_order() {
        let sw = "node 1 6041:00 Statusword";
        assert!(score("stw", sw).is_some());
        assert!(score("statusword 1", sw).is_some());
        assert!(score("6041", sw).is_some());
        assert!(score("STATUS", sw).is_some(), "case is ignored");
        assert_eq!(score("wst", sw), None, "letters out of order");
        assert_eq!(score("status velocity", sw), None, "every word must match");
        assert_eq!(score("", sw), Some(0));
    }

    #[test]
    fn runs_and_word_starts_rank_first() {
        let q = "vel";
        let a = score(q, "node 1 606c:00 Velocity actual value").unwrap();
        let b = score(q, "node 1 6041:00 Statusword voltage enabled level").unwrap();
        assert!(a > b, "{a} {b}");
        let c = score("act", "node 1 606c:00 Velocity actual value").unwrap();
        let d = score("act", "node 1 6060:00 Modes of operation ... xactx").unwrap();
        assert!(c > d, "{c} {d}");
    }
}
