//! Shards of a Monte Carlo study: `--shard k/n`, and the runs of a shard counted from the
//! slot-major order of the runs (index = slot·(number of sizes) + size index, slot 0 the
//! deterministic run and slot r + 1 realisation r; shard k/n runs the indices ≡ k − 1
//! (mod n)) without listing them.

/// Shard k of n (1 ≤ k ≤ n).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub k: usize,
    pub n: usize,
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.k, self.n)
    }
}

/// Read `--shard k/n`.
pub fn parse_shard(text: &str) -> anyhow::Result<Shard> {
    let bad = || {
        anyhow::anyhow!(
            "--shard `{text}`: expected k/n with whole numbers 1 ≤ k ≤ n (e.g. --shard 3/8)"
        )
    };
    let (k, n) = text.split_once('/').ok_or_else(bad)?;
    let k: usize = k.trim().parse().map_err(|_| bad())?;
    let n: usize = n.trim().parse().map_err(|_| bad())?;
    if k < 1 || k > n {
        return Err(bad());
    }
    Ok(Shard { k, n })
}

/// One run of the study: a size (index into the size list) and a realisation (`None`: the
/// deterministic run).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Item {
    pub size: usize,
    pub realisation: Option<usize>,
}

/// The runs of one shard (or of the whole study), largest size first and within a size in
/// the order of the realisations, without listing them: a shard of R realisations and a
/// million shards is a few numbers per size, not a list of runs.
///
/// The runs of size s in shard k/n are the slots x with x·S + s ≡ k − 1 (mod n) (S sizes,
/// module docs): none, or every slot x0 + t·p with p = n/gcd(S, n).
#[derive(Clone, Debug)]
pub struct ShardRuns {
    /// Per size, largest first.
    per_size: Vec<SizeRuns>,
    /// Slots between two runs of one size in the shard.
    step: u128,
    realisations: u128,
}

#[derive(Clone, Copy, Debug)]
struct SizeRuns {
    size: usize,
    /// The deterministic run (slot 0) is in the shard.
    deterministic: bool,
    /// First realisation slot (≥ 1) in the shard, and how many realisations of this size.
    first_slot: u128,
    count: u128,
    /// Realisations of the larger sizes before this one.
    before: u128,
}

fn gcd(a: u128, b: u128) -> u128 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// The inverse of `a` modulo `m` (gcd(a, m) = 1, m ≥ 2).
fn mod_inverse(a: u128, m: u128) -> u128 {
    // extended Euclid on (a, m) < 2^65: fits i128
    let (mut r0, mut r1) = (a as i128, m as i128);
    let (mut s0, mut s1) = (1i128, 0i128);
    while r1 != 0 {
        let q = r0 / r1;
        (r0, r1) = (r1, r0 - q * r1);
        (s0, s1) = (s1, s0 - q * s1);
    }
    s0.rem_euclid(m as i128) as u128
}

impl ShardRuns {
    /// The runs of `shard` (all runs without one) of `sizes` (D in m) × (1 deterministic +
    /// `realisations`).
    pub fn new(sizes: &[f64], realisations: usize, shard: Option<Shard>) -> ShardRuns {
        let ns = sizes.len() as u128;
        let (k, n) = shard.map_or((1, 1), |s| (s.k as u128, s.n as u128));
        let a = ns % n;
        let g = gcd(a, n);
        let step = n / g;
        let r = realisations as u128;
        let mut order: Vec<usize> = (0..sizes.len()).collect();
        order.sort_by(|&x, &y| sizes[y].total_cmp(&sizes[x]));
        let mut before = 0;
        let mut per_size = Vec::with_capacity(order.len());
        for size in order {
            let c = (k - 1 + n - size as u128 % n) % n;
            let (deterministic, first_slot, count) = if !c.is_multiple_of(g) {
                (false, 0, 0)
            } else {
                let x0 = if step == 1 {
                    0
                } else {
                    (c / g % step) * mod_inverse(a / g % step, step) % step
                };
                let first = if x0 == 0 { step } else { x0 };
                let count = if first > r { 0 } else { (r - first) / step + 1 };
                (x0 == 0, first, count)
            };
            per_size.push(SizeRuns {
                size,
                deterministic,
                first_slot,
                count,
                before,
            });
            before += count;
        }
        ShardRuns {
            per_size,
            step,
            realisations: before,
        }
    }

    /// Realisation runs in the shard.
    pub fn realisations(&self) -> u128 {
        self.realisations
    }

    /// Size indices whose deterministic run is in the shard, largest size first.
    pub fn deterministic(&self) -> Vec<usize> {
        self.per_size
            .iter()
            .filter(|s| s.deterministic)
            .map(|s| s.size)
            .collect()
    }

    /// Realisation runs of size index `size` in the shard.
    pub fn realisations_of(&self, size: usize) -> u128 {
        self.per_size
            .iter()
            .find(|s| s.size == size)
            .map_or(0, |s| s.count)
    }

    /// Realisation run `j` (0 ≤ j < [`Self::realisations`]) of the shard.
    pub fn realisation(&self, j: usize) -> Item {
        let j = j as u128;
        let s = self
            .per_size
            .iter()
            .find(|s| j >= s.before && j < s.before + s.count)
            .expect("realisation run index in the shard");
        let slot = s.first_slot + (j - s.before) * self.step;
        Item {
            size: s.size,
            realisation: Some((slot - 1) as usize),
        }
    }

    /// The index of the first realisation run of each size that has one (probes).
    pub fn first_of_each_size(&self) -> Vec<usize> {
        self.per_size
            .iter()
            .filter(|s| s.count > 0)
            .map(|s| s.before as usize)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shard_needs_one_le_k_le_n() {
        assert_eq!(parse_shard("2/5").unwrap(), Shard { k: 2, n: 5 });
        for bad in ["0/2", "3/2", "1", "a/2", "1/0", "-1/2"] {
            let e = parse_shard(bad).unwrap_err().to_string();
            assert!(e.contains("--shard") && e.contains(bad), "{e}");
        }
    }

    /// The runs of a shard by the definition: every index slot·S + size ≡ k − 1 (mod n),
    /// listed slot-major.
    fn shard_items(sizes: usize, realisations: usize, shard: Option<Shard>) -> Vec<Item> {
        let mut out = Vec::new();
        for slot in 0..=realisations {
            for size in 0..sizes {
                let index = slot * sizes + size;
                if shard.is_none_or(|s| index % s.n == s.k - 1) {
                    out.push(Item {
                        size,
                        realisation: slot.checked_sub(1),
                    });
                }
            }
        }
        out
    }

    /// A shard's runs as [`ShardRuns`] makes them: the deterministic runs, then the
    /// realisations in the order they are taken.
    fn planned(sizes: &[f64], realisations: usize, shard: Option<Shard>) -> Vec<Item> {
        let plan = ShardRuns::new(sizes, realisations, shard);
        let mut v: Vec<Item> = plan
            .deterministic()
            .into_iter()
            .map(|size| Item {
                size,
                realisation: None,
            })
            .collect();
        v.extend((0..plan.realisations() as usize).map(|j| plan.realisation(j)));
        v
    }

    #[test]
    fn shard_runs_are_the_definition_largest_size_first() {
        for ns in 1..=6 {
            // sizes ascending as parse_sizes returns them; descending too
            let asc: Vec<f64> = (1..=ns).map(|i| 0.05 * i as f64).collect();
            let desc: Vec<f64> = asc.iter().rev().copied().collect();
            for sizes in [asc, desc] {
                for r in 0..=9 {
                    for n in 1..=8 {
                        for k in 1..=n {
                            let shard = Some(Shard { k, n });
                            let got = planned(&sizes, r, shard);
                            let mut want = shard_items(ns, r, shard);
                            // largest size first, then deterministic, then by realisation
                            want.sort_by(|a, b| {
                                (a.realisation.is_some())
                                    .cmp(&b.realisation.is_some())
                                    .then(sizes[b.size].total_cmp(&sizes[a.size]))
                                    .then(a.realisation.cmp(&b.realisation))
                            });
                            assert_eq!(got, want, "sizes {sizes:?}, N = {r}, shard {k}/{n}");
                        }
                    }
                }
            }
        }
        assert_eq!(planned(&[0.1, 0.2], 3, None).len(), 8);
    }

    #[test]
    fn shard_runs_of_huge_counts_are_counted_not_listed() {
        // 2 sizes × (2^64 − 1 + 1) runs over a million shards: 36 893 488 147 420 or …421
        let plan = ShardRuns::new(&[0.05, 0.1], usize::MAX, Some(Shard { k: 1, n: 1_000_000 }));
        let total = plan.realisations() + plan.deterministic().len() as u128;
        let all = 2 * (usize::MAX as u128 + 1);
        assert_eq!(total, all.div_ceil(1_000_000));
        // the last shard of 7 of 3 sizes × 4 slots = 12 runs: runs 6 (size 0, slot 2) only
        let plan = ShardRuns::new(&[0.05, 0.1, 0.2], 3, Some(Shard { k: 7, n: 7 }));
        assert_eq!(plan.realisations(), 1);
        assert_eq!(
            plan.realisation(0),
            Item {
                size: 0,
                realisation: Some(1)
            }
        );
        // a shard beyond the runs is empty
        let plan = ShardRuns::new(&[0.05], 1, Some(Shard { k: 5, n: 9 }));
        assert_eq!((plan.realisations(), plan.deterministic().len()), (0, 0));
    }

    #[test]
    fn shards_are_disjoint_and_cover_the_runs() {
        let sizes = [0.05, 0.1, 0.2, 0.4, 0.8, 1.6];
        let all = planned(&sizes, 7, None);
        assert_eq!(all.len(), 6 * 8);
        for n in 1..=5 {
            let mut union: Vec<Item> = (1..=n)
                .flat_map(|k| planned(&sizes, 7, Some(Shard { k, n })))
                .collect();
            let len = union.len();
            union.sort();
            union.dedup();
            assert_eq!(union.len(), len, "shards of {n} overlap");
            let mut want = all.clone();
            want.sort();
            assert_eq!(union, want, "shards of {n} do not cover the runs");
        }
        // adding realisations keeps every earlier run in its shard
        let s = Some(Shard { k: 2, n: 3 });
        let small = planned(&sizes, 3, s);
        let large = planned(&sizes, 9, s);
        assert!(small.iter().all(|i| large.contains(i)));
    }
}
