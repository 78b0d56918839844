//! Payloads of any size as replies in pieces.
//!
//! attsync's sessions use Zenoh's low-latency transport (`zconfig`), which
//! writes each message from the calling thread but does not fragment: a
//! message larger than one batch (64 KiB) is an error that closes the link
//! (`zenoh-transport` 1.10, `unicast/lowlatency`). A run's request (every
//! node's configuration) and a host's end reply (every node's log tail) are
//! larger on big runs, so they travel as replies to one query, each
//! [`PIECE`] bytes at most behind an 8-byte header (its index and the
//! number of pieces, little-endian `u32`s), and are put back together by
//! [`collect`]. Everything else attsync sends across hosts is far smaller
//! than a batch.

use zenoh::Wait;
use zenoh::handlers::FifoChannelHandler;
use zenoh::query::{Query, Reply};

/// Payload bytes per piece: well under one batch with Zenoh's own headers.
pub const PIECE: usize = 32 << 10;

/// A piece's header: its index and the number of pieces.
const HEADER: usize = 8;

/// The most pieces a payload may claim (2 GiB of it): a hostile header
/// cannot make the receiver allocate more.
pub const MAX_PIECES: u32 = 1 << 16;

/// `bytes` as pieces (one empty piece for an empty payload).
#[must_use]
pub fn split(bytes: &[u8]) -> Vec<Vec<u8>> {
    let chunks: Vec<&[u8]> = if bytes.is_empty() {
        vec![&[]]
    } else {
        bytes.chunks(PIECE).collect()
    };
    let count = u32::try_from(chunks.len()).expect("under 2^32 pieces");
    (chunks.iter().zip(0u32..))
        .map(|(c, i)| {
            let mut p = Vec::with_capacity(HEADER + c.len());
            p.extend_from_slice(&i.to_le_bytes());
            p.extend_from_slice(&count.to_le_bytes());
            p.extend_from_slice(c);
            p
        })
        .collect()
}

/// Why pieces do not make a payload.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PieceError {
    /// A piece shorter than its header.
    #[error("a piece of {0} bytes, shorter than its header")]
    Short(usize),
    /// A piece whose header disagrees with the first one's.
    #[error("piece {index} of {count} does not belong to a payload of {expected} pieces")]
    Mismatch {
        /// Its index.
        index: u32,
        /// The count it claims.
        count: u32,
        /// The count of the first piece.
        expected: u32,
    },
    /// A header claiming more than [`MAX_PIECES`].
    #[error("a payload of {0} pieces, more than {MAX_PIECES}")]
    TooMany(u32),
    /// The same piece twice.
    #[error("piece {0} came twice")]
    Twice(u32),
    /// The replies ended before every piece came.
    #[error("{missing} of its {count} pieces did not come")]
    Missing {
        /// Pieces that did not come.
        missing: usize,
        /// Pieces of the payload.
        count: u32,
    },
}

/// A payload being put back together.
#[derive(Debug, Default)]
pub struct Assembly {
    parts: Vec<Option<Vec<u8>>>,
    got: usize,
}

impl Assembly {
    /// Adds `piece`; `true` once every piece is in.
    pub fn add(&mut self, piece: &[u8]) -> Result<bool, PieceError> {
        let (Some(head), Some(data)) = (piece.get(..HEADER), piece.get(HEADER..)) else {
            return Err(PieceError::Short(piece.len()));
        };
        let word = |k: usize| u32::from_le_bytes(head[k..k + 4].try_into().expect("4 bytes"));
        let (index, count) = (word(0), word(4));
        if count > MAX_PIECES {
            return Err(PieceError::TooMany(count));
        }
        if self.parts.is_empty() {
            self.parts = vec![None; count as usize];
        }
        let expected = u32::try_from(self.parts.len()).unwrap_or(u32::MAX);
        if count != expected || index >= count {
            return Err(PieceError::Mismatch {
                index,
                count,
                expected,
            });
        }
        let slot = &mut self.parts[index as usize];
        if slot.is_some() {
            return Err(PieceError::Twice(index));
        }
        *slot = Some(data.to_vec());
        self.got += 1;
        Ok(self.got == self.parts.len())
    }

    /// The whole payload, if every piece came.
    pub fn finish(self) -> Result<Vec<u8>, PieceError> {
        let count = u32::try_from(self.parts.len()).unwrap_or(u32::MAX);
        let missing = self.parts.iter().filter(|p| p.is_none()).count();
        if missing > 0 || self.parts.is_empty() {
            return Err(PieceError::Missing {
                missing: missing.max(1),
                count,
            });
        }
        Ok(self.parts.into_iter().flatten().flatten().collect())
    }
}

/// Replies `bytes` to `q`, in pieces.
pub fn reply(q: &Query, bytes: &[u8]) {
    for p in split(bytes) {
        let _ = q.reply(q.key_expr().clone(), p).wait();
    }
}

/// Why a get's replies are not a payload.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum CollectError {
    /// Nothing came before the get ended (its timeout).
    #[error("no answer")]
    NoAnswer,
    /// An error reply (its text).
    #[error("{0}")]
    Refused(String),
    /// The pieces that came do not make a payload.
    #[error("a reply in pieces: {0}")]
    Pieces(#[from] PieceError),
}

/// The payload replied in pieces ([`reply`]) to one get, put back together.
pub fn collect(replies: &FifoChannelHandler<Reply>) -> Result<Vec<u8>, CollectError> {
    let mut assembly = Assembly::default();
    let mut any = false;
    while let Ok(r) = replies.recv() {
        match r.result() {
            Ok(s) => {
                any = true;
                if assembly.add(&s.payload().to_bytes())? {
                    return Ok(assembly.finish()?);
                }
            }
            Err(e) => {
                let text = String::from_utf8_lossy(&e.payload().to_bytes()).into_owned();
                return Err(CollectError::Refused(text));
            }
        }
    }
    if any {
        Err(assembly
            .finish()
            .err()
            .map_or(CollectError::NoAnswer, Into::into))
    } else {
        Err(CollectError::NoAnswer)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn roundtrip(bytes: &[u8], order: impl Fn(usize) -> Vec<usize>) -> Vec<u8> {
        let pieces = split(bytes);
        let mut a = Assembly::default();
        let ix = order(pieces.len());
        for (k, &i) in ix.iter().enumerate() {
            let done = a.add(&pieces[i]).unwrap();
            assert_eq!(done, k + 1 == pieces.len());
        }
        a.finish().unwrap()
    }

    #[test]
    fn any_payload_comes_back_whole_in_any_order() {
        for len in [0, 1, PIECE - 1, PIECE, PIECE + 1, 5 * PIECE + 17] {
            let bytes: Vec<u8> = (0..len).map(|i| (i * 31 % 251) as u8).collect();
            assert_eq!(roundtrip(&bytes, |n| (0..n).collect()), bytes, "{len}");
            assert_eq!(
                roundtrip(&bytes, |n| (0..n).rev().collect()),
                bytes,
                "{len}"
            );
        }
    }

    #[test]
    fn every_piece_fits_a_batch() {
        let bytes = vec![7u8; 10 * PIECE + 3];
        let pieces = split(&bytes);
        assert_eq!(pieces.len(), 11);
        assert!(pieces.iter().all(|p| p.len() <= HEADER + PIECE));
        const {
            assert!(
                HEADER + PIECE < 60 << 10,
                "room for Zenoh's headers in 64 KiB"
            )
        };
    }

    #[test]
    fn a_missing_twice_or_foreign_piece_is_refused() {
        let p = split(&vec![1u8; 3 * PIECE]);
        let mut a = Assembly::default();
        a.add(&p[0]).unwrap();
        assert_eq!(a.add(&p[0]), Err(PieceError::Twice(0)));
        let foreign = &split(&[1u8; 10])[0];
        assert!(matches!(a.add(foreign), Err(PieceError::Mismatch { .. })));
        assert_eq!(a.add(&[1, 2, 3]), Err(PieceError::Short(3)));
        let huge = [0, 0, 0, 0, 0xff, 0xff, 0xff, 0xff];
        assert_eq!(a.add(&huge), Err(PieceError::TooMany(u32::MAX)));
        a.add(&p[2]).unwrap();
        assert_eq!(
            a.finish(),
            Err(PieceError::Missing {
                missing: 1,
                count: 3
            })
        );
        assert!(matches!(
            Assembly::default().finish(),
            Err(PieceError::Missing { .. })
        ));
    }
}
