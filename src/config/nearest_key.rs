//! The valid name a user most likely meant by one the configuration does
//! not have: the same name with its unit left off (`roughness.sigma` →
//! `roughness.sigma_m`, `contact.load` → `load_n`), or a typo of one
//! (`boundary_fricton` → `boundary_friction`: at most a third of its
//! letters edited, Damerau–Levenshtein).

/// The name of `names` nearest to `given`, when one is near enough (see
/// the module); None when none is, or when two are equally near.
pub fn nearest<'a>(given: &str, names: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let names: Vec<&str> = names.into_iter().collect();
    let with_unit: Vec<&str> = names
        .iter()
        .copied()
        .filter(|n| n.strip_prefix(given).is_some_and(|u| u.starts_with('_')))
        .collect();
    if let [one] = with_unit[..] {
        return Some(one);
    }
    let limit = (given.chars().count() / 3).max(1);
    let mut by_distance: Vec<(usize, &str)> = names
        .iter()
        .map(|n| (strsim::damerau_levenshtein(given, n), *n))
        .filter(|(d, _)| *d <= limit)
        .collect();
    by_distance.sort();
    match by_distance[..] {
        [(d, n), (e, _), ..] if d < e => Some(n),
        [(_, n)] => Some(n),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::nearest;

    #[test]
    fn a_name_without_its_unit_or_with_a_typo_finds_the_key_and_a_stranger_none() {
        let keys = [
            "length_m",
            "load_n",
            "boundary_friction",
            "boundary_friction_rate",
        ];
        assert_eq!(nearest("load", keys), Some("load_n"));
        assert_eq!(nearest("boundary_fricton", keys), Some("boundary_friction"));
        assert_eq!(nearest("lenght_m", keys), Some("length_m"));
        assert_eq!(nearest("colour", keys), None);
        // Two keys as near: no guess.
        assert_eq!(nearest("x_n", ["a_n", "b_n"]), None);
    }
}
