//! Sub-entries written once for a range of subs (`"1..254": {"name": "Standard error
//! field {n}"}`), kept as one template and turned into entries only when one of them is
//! first looked up or listed. CiA 301 alone has about 4000 such entries, and building them
//! all was most of every command's start-up.

use std::sync::OnceLock;

use super::object::ObjectInfo;

/// The entries of one index at subs `first..=last`, made from one template.
#[derive(Clone, Debug)]
pub struct SubFamily {
    first: u8,
    last: u8,
    /// The entry, with `{n}` in its name standing for the sub.
    template: ObjectInfo,
    /// The entries, made on first use.
    entries: OnceLock<Vec<ObjectInfo>>,
}

impl SubFamily {
    /// A family of the subs `first..=last` (`first <= last`) made from `template`.
    pub fn new(first: u8, last: u8, template: ObjectInfo) -> SubFamily {
        SubFamily {
            first,
            last: last.max(first),
            template,
            entries: OnceLock::new(),
        }
    }

    /// The subs it covers.
    pub fn subs(&self) -> std::ops::RangeInclusive<u8> {
        self.first..=self.last
    }

    /// The template entry (`{n}` not yet replaced).
    pub fn template(&self) -> &ObjectInfo {
        &self.template
    }

    /// The entry at `sub`, `None` outside the family.
    pub fn get(&self, sub: u8) -> Option<&ObjectInfo> {
        let at = sub.checked_sub(self.first)?;
        self.entries().get(usize::from(at))
    }

    /// Every entry with its sub, rising.
    pub fn iter(&self) -> impl Iterator<Item = (u8, &ObjectInfo)> {
        self.subs().zip(self.entries())
    }

    fn entries(&self) -> &[ObjectInfo] {
        self.entries
            .get_or_init(|| self.subs().map(|n| self.entry(n)).collect())
    }

    /// The template made into the entry at `sub`.
    fn entry(&self, sub: u8) -> ObjectInfo {
        ObjectInfo {
            name: fill(&self.template.name, "{n}", sub.into()),
            ..self.template.clone()
        }
    }
}

/// `template` with every `slot` (e.g. `{i}`) replaced by `value`.
pub(super) fn fill(template: &str, slot: &str, value: u32) -> String {
    Numbered::new(template, slot).with(value)
}

/// A name template split at its slot (`{i}`, `{n}`) once, to be filled for many numbers:
/// the thousands of range names of CiA 301 made `str::replace` a third of the start-up.
pub(super) struct Numbered<'a> {
    /// The text between the slots.
    parts: Vec<&'a str>,
    /// Bytes of text.
    len: usize,
}

impl<'a> Numbered<'a> {
    /// `template` split at every `slot`.
    pub(super) fn new(template: &'a str, slot: &str) -> Numbered<'a> {
        let parts: Vec<&str> = template.split(slot).collect();
        Numbered {
            len: parts.iter().map(|p| p.len()).sum(),
            parts,
        }
    }

    /// The template with `value` in decimal at every slot.
    pub(super) fn with(&self, value: u32) -> String {
        let mut digits = [0u8; 10];
        let mut at = digits.len();
        let mut v = value;
        loop {
            at -= 1;
            digits[at] = b'0' + (v % 10) as u8;
            v /= 10;
            if v == 0 {
                break;
            }
        }
        let number = std::str::from_utf8(&digits[at..]).unwrap_or_default();
        let mut out = String::with_capacity(self.len + number.len() * (self.parts.len() - 1));
        let (first, rest) = self.parts.split_first().map_or(("", &[][..]), |(f, r)| (*f, r));
        out.push_str(first);
        for part in rest {
            out.push_str(number);
            out.push_str(part);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn family() -> SubFamily {
        let template = ObjectInfo {
            name: "Node {n} ({n})".into(),
            description: Some("kept".into()),
            ..Default::default()
        };
        SubFamily::new(2, 5, template)
    }

    #[test]
    fn an_entry_is_the_template_with_its_sub_in_the_name() {
        let f = family();
        assert_eq!(f.get(4).unwrap().name, "Node 4 (4)");
        assert_eq!(f.get(4).unwrap().description.as_deref(), Some("kept"));
        assert!(f.get(1).is_none() && f.get(6).is_none());
    }

    #[test]
    fn iteration_gives_every_sub_once_rising() {
        let names: Vec<(u8, String)> = family().iter().map(|(s, o)| (s, o.name.clone())).collect();
        let want: Vec<(u8, String)> = (2..=5).map(|n| (n, format!("Node {n} ({n})"))).collect();
        assert_eq!(names, want);
    }

    #[test]
    fn fill_keeps_other_braces() {
        assert_eq!(fill("a{x}{n}b{", "{n}", 254), "a{x}254b{");
    }
}
