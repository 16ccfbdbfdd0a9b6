//! Suggestions for misspelt names: the closest known names by edit distance.

/// Levenshtein distance of `a` and `b` (in chars), stopping early above `cap`.
fn distance(a: &str, b: &str, cap: usize) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        let mut best = row[0];
        for j in 0..b.len() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != b[j])).min(row[j] + 1).min(cur + 1);
            prev = cur;
            best = best.min(row[j + 1]);
        }
        if best > cap {
            return cap + 1;
        }
    }
    row[b.len()]
}

/// The known names closest to `name`: at most 3, within an edit distance of a third of
/// the name's length (at least 2), or containing it / contained in it (case-insensitive).
pub fn closest<'a>(name: &str, known: impl IntoIterator<Item = &'a str>) -> Vec<&'a str> {
    let cap = (name.chars().count() / 3).max(2);
    let lower = name.to_lowercase();
    let mut scored: Vec<(usize, &str)> = known
        .into_iter()
        .filter_map(|k| {
            let d = distance(&lower, &k.to_lowercase(), cap);
            let kl = k.to_lowercase();
            if d <= cap {
                Some((d, k))
            } else if lower.len() >= 3 && (kl.contains(&lower) || lower.contains(&kl) && kl.len() >= 3) {
                Some((cap + 1, k))
            } else {
                None
            }
        })
        .collect();
    scored.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.cmp(b.1)));
    scored.into_iter().take(3).map(|(_, k)| k).collect()
}

/// `"; did you mean \"x\"?"` for the closest names, or `" (kind: a, b, c)"` listing all
/// known names when there are at most 12 and none is close, or "" .
pub fn did_you_mean<'a>(name: &str, known: impl IntoIterator<Item = &'a str> + Clone, kind: &str) -> String {
    let close = closest(name, known.clone());
    if !close.is_empty() {
        let quoted: Vec<String> = close.iter().map(|c| format!("{c:?}")).collect();
        return format!("; did you mean {}?", quoted.join(" or "));
    }
    let all: Vec<&str> = known.into_iter().collect();
    if all.is_empty() {
        format!(" (there are no {kind})")
    } else if all.len() <= 12 {
        format!(" ({kind}: {})", all.join(", "))
    } else {
        String::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edit_distance_and_suggestions() {
        assert_eq!(distance("kitten", "sitting", 10), 3);
        assert_eq!(distance("", "abc", 10), 3);
        assert_eq!(distance("v_x_strat", "v_x_start", 10), 2);
        let names = ["v_x_start", "v_y_start", "delta_fl", "x"];
        assert_eq!(closest("v_x_strat", names), ["v_x_start", "v_y_start"]);
        assert_eq!(closest("DELTA_FL", names), ["delta_fl"]);
        assert!(closest("zzzzzzzz", names).is_empty());
        assert_eq!(did_you_mean("delta_f", names, "variables"), "; did you mean \"delta_fl\"?");
        assert_eq!(did_you_mean("qqqqqq", ["a", "b"], "instances"), " (instances: a, b)");
    }
}
