//! The search job: finds every frame of the trace that matches a search (within the
//! filter in force) in the background, in slices like a filtered view, and answers
//! "next/previous match from here" from what it has found, wrapping around once the
//! whole trace is searched. A jump asked for before its match is found waits
//! ([`Search::ask`], [`Search::poll`]); nothing moves until then.

use super::filter::Filter;
use super::trace::Trace;
use super::view::View;
use std::time::Duration;

/// The answer to "where is the next (previous) match".
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Found {
    /// At this trace position; `wrapped` when it is past the end (start) of the trace.
    At {
        /// Trace position.
        pos: usize,
        /// The search went round the end (or start) of the trace.
        wrapped: bool,
    },
    /// The part of the trace where it would be is not searched yet.
    Searching,
    /// The whole trace is searched: no match at all.
    Nothing,
}

/// A search running over the trace.
pub struct Search {
    /// The search as typed.
    pub filter: Filter,
    /// Its matches: frames matching the filter in force and the search.
    view: View,
    /// A jump waiting for its match: from this position (none: from before the first
    /// frame), forward or back.
    want: Option<(Option<usize>, bool)>,
}

impl Search {
    /// A search for `search` among the frames `within` lets through.
    pub fn new(search: Filter, within: &Filter) -> Search {
        Search {
            view: View::new(within.and(&search)),
            filter: search,
            want: None,
        }
    }

    /// Searches on for up to `budget` (at least one slice); true when work is left.
    pub fn advance(&mut self, trace: &Trace, budget: Duration) -> bool {
        self.view.advance(trace, budget)
    }

    /// No more frames will come (see [`View::settle`]).
    pub fn settle(&mut self) {
        self.view.settle();
    }

    /// Matches found so far.
    pub fn count(&self) -> usize {
        self.view.positions().len()
    }

    /// Percent of the trace searched.
    pub fn progress(&self, trace: &Trace) -> u8 {
        self.view.progress(trace)
    }

    /// True when every frame of the trace is searched.
    pub fn complete(&self, trace: &Trace) -> bool {
        self.view.scanned() >= trace.len()
    }

    /// 1-based rank of the match at `pos` among all matches.
    pub fn rank(&self, pos: usize) -> usize {
        self.view.row_of(pos) + 1
    }

    /// The next match after `from` (forward) or the previous one before it, as far as
    /// the trace is searched; `from` none means before the first frame.
    pub fn find(&self, trace: &Trace, from: Option<usize>, forward: bool) -> Found {
        let m = self.view.positions();
        let complete = self.complete(trace);
        let near = if forward {
            let i = from.map_or(0, |f| m.partition_point(|&p| p as usize <= f));
            m.get(i)
        } else {
            let f = from.unwrap_or(0);
            let i = m.partition_point(|&p| (p as usize) < f);
            // Matches before `from` are all known once the search went past it.
            (i > 0 && self.view.scanned() > f).then(|| &m[i - 1])
        };
        match (near, complete) {
            (Some(&p), _) => Found::At {
                pos: p as usize,
                wrapped: false,
            },
            (None, false) => Found::Searching,
            (None, true) => match if forward { m.first() } else { m.last() } {
                Some(&p) => Found::At {
                    pos: p as usize,
                    wrapped: true,
                },
                None => Found::Nothing,
            },
        }
    }

    /// Keeps a jump that [`Search::find`] could not answer yet.
    pub fn ask(&mut self, from: Option<usize>, forward: bool) {
        self.want = Some((from, forward));
    }

    /// The answer to the waiting jump once the search found it (or found there is none).
    pub fn poll(&mut self, trace: &Trace) -> Option<Found> {
        let (from, forward) = self.want?;
        match self.find(trace, from, forward) {
            Found::Searching => None,
            found => {
                self.want = None;
                Some(found)
            }
        }
    }

    /// True while a jump waits for its match.
    pub fn waiting(&self) -> bool {
        self.want.is_some()
    }

    /// For the status bar: `search: TEXT (N matches)`, with the percent searched while
    /// it runs.
    pub fn summary(&self, trace: &Trace) -> String {
        let n = self.count();
        let s = if n == 1 { "" } else { "es" };
        if self.complete(trace) {
            format!("search: {} ({n} match{s})", self.filter.source)
        } else {
            format!(
                "search: {} ({n} match{s} so far, {}%)",
                self.filter.source,
                self.progress(trace)
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decode::Decoder;
    use crate::od::Dictionary;

    #[test]
    fn finds_wraps_and_waits_for_the_part_not_searched_yet() {
        let mut t = Trace::new(Decoder::new(Dictionary::default(), Vec::new()), 500_000);
        let frames: Vec<crate::frame::Frame> = crate::sim::synth::Traffic::new(50_000, 0).collect();
        for f in &frames {
            t.push(f);
        }
        let hb = |n| Filter::parse(&format!("hb node {n}")).unwrap();
        let mut s = Search::new(hb(2), &Filter::default());
        // Nothing searched: every answer waits, and an asked jump stays asked.
        assert_eq!(s.find(&t, Some(10), true), Found::Searching);
        s.ask(Some(10), true);
        assert_eq!(s.poll(&t), None);
        assert!(s.waiting());
        // One slice searched (2048 frames): the first match after 10 is known.
        s.advance(&t, Duration::ZERO);
        assert!(!s.complete(&t));
        let Some(Found::At {
            pos: first,
            wrapped: false,
        }) = s.poll(&t)
        else {
            panic!("no match found in the first slice")
        };
        assert_eq!(t.store.packed(first).id, 0x702);
        assert!(s.summary(&t).contains("so far"), "{}", s.summary(&t));
        // The previous match before the first one is not known until the end is searched.
        assert_eq!(s.find(&t, Some(first), false), Found::Searching);
        while s.advance(&t, Duration::from_millis(50)) {}
        let last = (0..t.len()).rev().find(|&p| t.store.packed(p).id == 0x702).unwrap();
        assert_eq!(
            s.find(&t, Some(first), false),
            Found::At {
                pos: last,
                wrapped: true
            }
        );
        assert_eq!(
            s.find(&t, Some(last), true),
            Found::At {
                pos: first,
                wrapped: true
            }
        );
        assert_eq!(s.rank(last), s.count());
        assert_eq!(s.summary(&t), format!("search: hb node 2 ({} matches)", s.count()));
        // Within a filter that excludes node 2, nothing is found.
        let mut none = Search::new(hb(2), &Filter::parse("node 3").unwrap());
        while none.advance(&t, Duration::from_millis(50)) {}
        assert_eq!(none.find(&t, None, true), Found::Nothing);
    }
}
