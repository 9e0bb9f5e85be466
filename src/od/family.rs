//! Sub-entries written once for a range of subs (`"1..254": {"name": "Standard error
//! field {n}"}`), kept as one template and turned into entries only when one of them is
//! first looked up or listed. CiA 301 alone has about 4000 such entries, and building them
//! all was most of every command's start-up.

use std::sync::OnceLock;

use super::ObjectInfo;

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

/// `template` with every `slot` (e.g. `{i}`) replaced by `value`: a byte search for `{`
/// and hand-made digits, because `str::replace` plus `to_string` made up a third of the
/// start-up time for the thousands of range names of CiA 301.
pub(super) fn fill(template: &str, slot: &str, value: u32) -> String {
    let mut out = String::with_capacity(template.len() + 8);
    let mut rest = template;
    while let Some(at) = rest.find('{') {
        let (before, tail) = rest.split_at(at);
        out.push_str(before);
        match tail.strip_prefix(slot) {
            Some(after) => {
                push_decimal(&mut out, value);
                rest = after;
            }
            None => {
                out.push('{');
                rest = &tail[1..];
            }
        }
    }
    out.push_str(rest);
    out
}

/// Appends `v` in decimal.
fn push_decimal(out: &mut String, mut v: u32) {
    let mut digits = [0u8; 10];
    let mut n = digits.len();
    loop {
        n -= 1;
        digits[n] = b'0' + (v % 10) as u8;
        v /= 10;
        if v == 0 {
            break;
        }
    }
    out.extend(digits[n..].iter().map(|&d| char::from(d)));
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
