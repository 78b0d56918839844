//! Agent ids: every valid id once, ascending, with its `[[agent]]` index,
//! and each id's *rank* (its place in that order: the agent's index in the
//! network and in `Ξ + LLᵀ`). Later phases keep per-agent data in vectors
//! by rank instead of maps by id.

/// The known agent ids, ascending.
pub(super) struct Ids {
    /// `(id, index in [[agent]])`, ascending by id; a repeated id keeps its
    /// first index.
    sorted: Vec<(u32, usize)>,
    /// Whether the ids are exactly `1..=len` (then `rank(id) = id − 1`).
    dense: bool,
}

impl Ids {
    /// The ids of `(id, index)` pairs given in file order (id 0 left out by
    /// the caller), and the indices (ascending) that repeat an earlier id,
    /// each with the index it repeats.
    pub(super) fn new(mut pairs: Vec<(u32, usize)>) -> (Self, Vec<(usize, usize)>) {
        pairs.sort_unstable();
        let mut repeats = Vec::new();
        pairs.dedup_by(|later, first| {
            let same = later.0 == first.0;
            if same {
                repeats.push((later.1, first.1));
            }
            same
        });
        repeats.sort_unstable();
        let dense = pairs
            .iter()
            .enumerate()
            .all(|(r, &(id, _))| u64::from(id) == r as u64 + 1);
        (
            Self {
                sorted: pairs,
                dense,
            },
            repeats,
        )
    }

    /// Number of distinct ids.
    pub(super) fn len(&self) -> usize {
        self.sorted.len()
    }

    /// The rank of `id`, if it is a known agent.
    pub(super) fn rank(&self, id: u32) -> Option<usize> {
        if self.dense {
            let r = (id as usize).checked_sub(1)?;
            return (r < self.sorted.len()).then_some(r);
        }
        self.sorted.binary_search_by_key(&id, |&(x, _)| x).ok()
    }

    /// Whether `id` is a known agent.
    pub(super) fn contains(&self, id: u32) -> bool {
        self.rank(id).is_some()
    }

    /// The id of rank `r`.
    pub(super) fn id(&self, r: usize) -> u32 {
        self.sorted[r].0
    }

    /// `(id, index in [[agent]])`, ascending by id.
    pub(super) fn iter(&self) -> impl Iterator<Item = (u32, usize)> + '_ {
        self.sorted.iter().copied()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranks_of_dense_and_sparse_ids() {
        let (ids, repeats) = Ids::new(vec![(2, 0), (1, 1), (3, 2)]);
        assert!(repeats.is_empty());
        assert_eq!(
            [0, 1, 2, 3, 4].map(|id| ids.rank(id)),
            [None, Some(0), Some(1), Some(2), None]
        );
        let (ids, repeats) = Ids::new(vec![(10, 0), (7, 1), (10, 2), (7, 3), (99, 4)]);
        assert_eq!(repeats, [(2, 0), (3, 1)]);
        assert_eq!(ids.iter().collect::<Vec<_>>(), [(7, 1), (10, 0), (99, 4)]);
        assert_eq!(
            [7, 10, 99, 8].map(|id| ids.rank(id)),
            [Some(0), Some(1), Some(2), None]
        );
        assert_eq!(ids.id(1), 10);
    }
}
