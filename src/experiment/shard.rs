//! Sharding: one experiment split across machines or processes, each running a disjoint slice.

use std::fmt;
use std::str::FromStr;

/// A bad `--shard` value.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("shard '{spec}': {what}")]
pub struct ShardError {
    pub spec: String,
    pub what: String,
}

/// The `index`-th of `count` disjoint slices of an experiment's units, written `k/n` with
/// `1 <= k <= n`.
///
/// Unit `i` (0-based, in the experiment's order) belongs to shard `(i mod n) + 1`: round robin
/// rather than contiguous blocks, so that every shard gets a similar mix of cheap and expensive
/// settings (units are usually listed setting by setting). The `n` shards together cover every
/// unit exactly once.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Shard {
    index: u32,
    count: u32,
}

impl Shard {
    /// The whole experiment, `1/1`.
    pub const WHOLE: Shard = Shard { index: 1, count: 1 };

    pub fn new(index: u32, count: u32) -> Result<Self, ShardError> {
        let spec = format!("{index}/{count}");
        if count == 0 {
            return Err(ShardError {
                spec,
                what: "the number of shards n must be at least 1".into(),
            });
        }
        if index == 0 || index > count {
            return Err(ShardError {
                spec,
                what: format!("k must satisfy 1 <= k <= n = {count}"),
            });
        }
        Ok(Self { index, count })
    }

    /// `k`, 1-based.
    pub fn index(&self) -> u32 {
        self.index
    }

    /// `n`.
    pub fn count(&self) -> u32 {
        self.count
    }

    /// Whether unit number `unit_index` (0-based) is in this shard.
    pub fn contains(&self, unit_index: usize) -> bool {
        unit_index % self.count as usize == (self.index - 1) as usize
    }
}

impl Default for Shard {
    fn default() -> Self {
        Self::WHOLE
    }
}

impl FromStr for Shard {
    type Err = ShardError;

    fn from_str(spec: &str) -> Result<Self, ShardError> {
        let err = |what: &str| ShardError {
            spec: spec.to_string(),
            what: what.to_string(),
        };
        let (k, n) = spec
            .split_once('/')
            .ok_or_else(|| err("expected k/n, e.g. 2/3"))?;
        let k: u32 = k.trim().parse().map_err(|_| err("k is not a whole number"))?;
        let n: u32 = n.trim().parse().map_err(|_| err("n is not a whole number"))?;
        Self::new(k, n).map_err(|e| ShardError {
            spec: spec.to_string(),
            what: e.what,
        })
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_rejects() {
        assert_eq!("2/3".parse::<Shard>().unwrap(), Shard::new(2, 3).unwrap());
        assert_eq!("1/1".parse::<Shard>().unwrap(), Shard::WHOLE);
        for (bad, needle) in [
            ("0/3", "1 <= k <= n"),
            ("4/3", "1 <= k <= n"),
            ("1/0", "at least 1"),
            ("3", "k/n"),
            ("a/2", "k is"),
        ] {
            let e = bad.parse::<Shard>().unwrap_err().to_string();
            assert!(e.contains(bad) && e.contains(needle), "{bad}: {e}");
        }
    }

    #[test]
    fn shards_partition_the_units() {
        let n = 3;
        let shards: Vec<Shard> = (1..=n).map(|k| Shard::new(k, n).unwrap()).collect();
        for unit in 0..20 {
            assert_eq!(
                shards.iter().filter(|s| s.contains(unit)).count(),
                1,
                "unit {unit}"
            );
        }
        assert!((0..20).all(|u| Shard::WHOLE.contains(u)));
    }
}
