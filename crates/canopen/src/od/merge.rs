//! Presentation merged down the dictionary layers: an EDS says what a device has (name,
//! type, access, limits) but rarely how to show it, so an entry of a top layer takes the
//! unit and scale (as a pair), value texts, bit names and fields it lacks from the first lower layer
//! (vendor profile, CiA 402, CiA 301) that has them for the same (index, sub) and the same
//! data type. What the top layer gives itself always wins.

use super::object::ObjectInfo;
use super::profile::Profile;
use std::sync::Arc;

/// `top` with each entry completed from `lower` (first layer first); `None` when no
/// entry gains anything, so the caller keeps sharing the original.
pub(crate) fn enriched(top: &Profile, lower: &[Arc<Profile>]) -> Option<Profile> {
    let mut out: Option<Profile> = None;
    for ((index, sub), info) in top.entries() {
        let mut merged = info.clone();
        for layer in lower {
            if let Some(base) = layer.object(index, sub).filter(|b| b.data_type == info.data_type) {
                complete(&mut merged, base);
            }
        }
        if merged != *info {
            out.get_or_insert_with(|| top.clone())
                .objects
                .insert((index, sub), merged);
        }
    }
    out
}

/// Fills what `info` does not give from `base`.
fn complete(info: &mut ObjectInfo, base: &ObjectInfo) {
    // Unit and scale go together: an entry with its own unit keeps its own scaling.
    if info.unit.is_none() && info.scale.is_none() {
        info.unit.clone_from(&base.unit);
        info.scale = base.scale;
    }
    if info.values.is_empty() {
        info.values.clone_from(&base.values);
    }
    if info.bits.is_empty() {
        info.bits.clone_from(&base.bits);
    }
    if info.fields.is_empty() {
        info.fields.clone_from(&base.fields);
    }
    if info.meaning.is_none() {
        info.meaning = base.meaning;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::od::DataType;

    fn entry(unit: Option<&str>, scale: Option<f64>, data_type: DataType) -> ObjectInfo {
        ObjectInfo {
            name: "Max torque".into(),
            data_type,
            unit: unit.map(String::from),
            scale,
            ..Default::default()
        }
    }

    fn layer(info: ObjectInfo) -> Profile {
        let mut p = Profile::default();
        p.objects.insert((0x6072, 0), info);
        p
    }

    #[test]
    fn lower_layers_fill_only_what_is_missing_and_only_for_the_same_type() {
        let cia402 = Arc::new(layer(entry(Some("%"), Some(0.1), DataType::U16)));
        let bare = layer(entry(None, None, DataType::U16));
        let got = enriched(&bare, std::slice::from_ref(&cia402)).expect("completed");
        assert_eq!(got.objects[&(0x6072, 0)].unit.as_deref(), Some("%"));
        assert_eq!(got.objects[&(0x6072, 0)].scale, Some(0.1));

        let own = layer(entry(Some("mNm"), None, DataType::U16));
        assert!(
            enriched(&own, std::slice::from_ref(&cia402)).is_none(),
            "own unit, own scale"
        );

        let other_type = layer(entry(None, None, DataType::I32));
        assert!(enriched(&other_type, &[cia402]).is_none());
    }
}
