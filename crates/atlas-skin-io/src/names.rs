//! Unique names for joints and nodes read from files that allow duplicates.

use std::collections::HashSet;

/// `wanted` with later duplicates renamed `NAME.1`, `NAME.2`, … (the first keeps its name;
/// a suffix already taken is skipped).
pub(crate) fn unique_names(wanted: Vec<String>) -> Vec<String> {
    let mut taken = HashSet::new();
    wanted
        .into_iter()
        .map(|wanted| {
            let mut name = wanted.clone();
            let mut suffix = 0;
            while !taken.insert(name.clone()) {
                suffix += 1;
                name = format!("{wanted}.{suffix}");
            }
            name
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn duplicates_get_the_first_free_suffix() {
        let names = |n: &[&str]| n.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        assert_eq!(
            unique_names(names(&["a", "b", "a", "a.1", "a"])),
            names(&["a", "b", "a.1", "a.1.1", "a.2"])
        );
    }
}
