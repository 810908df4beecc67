//! Input messages lost before the planner read them, counted from the gaps in each
//! sender's header sequence (one counter across all of a sender's input services, see
//! `Header`).
//!
//! A subscriber's buffer gives way to the newest sample when it overflows, and iceoryx2
//! does not say so. But a sender numbers its messages 1, 2, 3, … across its services, so a
//! message the planner never reads leaves a hole in the sequences it does read. A hole is
//! not final at once: the planner drains its inputs one service after another, and a
//! message published on a service already drained in this pass is read in the next one.
//! It is final one pass later: a sequence below the highest read by the end of a pass was
//! published before that one, so before the next pass started, which reads it if it is
//! still buffered. So at the end of each pass the holes at or below the previous pass's
//! highest sequence are counted as lost.
//!
//! A sender is counted from the end of the first drain that reads it: what it published
//! before the planner's subscribers were there was never this planner's to read (a
//! restarted planner reads the history services' old samples and the live ones together,
//! thousands of sequences apart). The sequences of accepted messages advance a sender; a
//! rejected message whose header is readable fills its hole (it was read, not lost) but
//! moves nothing, so a garbage sequence cannot open a gap. A jump of more than [`WINDOW`] (a sender that restarted its
//! counter higher, say) starts the count afresh rather than counting the jump. At most
//! [`SENDERS`] senders are followed (the planner's inputs come from one or two); a further
//! one is not counted. Nothing here allocates.

use wingman_interfaces::Header;

/// Sequences a sender's record covers above the settled ones.
pub const WINDOW: u64 = 4096;
/// Senders followed.
pub const SENDERS: usize = 8;

const WORDS: usize = (WINDOW / 64) as usize;

/// One sender's record.
#[derive(Debug, Clone, Copy)]
struct Sender {
    id: u32,
    /// Every sequence up to this is settled: read, or counted as lost.
    settled: u64,
    /// The highest accepted sequence.
    max: u64,
    /// `max` at the end of the previous pass.
    max_at_last_pass: u64,
    /// The sequences read in `(settled, settled + WINDOW]`, bit `s % WINDOW`.
    read: [u64; WORDS],
    /// First read in the current drain: its holes so far are not counted.
    new: bool,
}

impl Sender {
    fn new(id: u32, sequence: u64) -> Sender {
        let mut s = Sender {
            id,
            settled: sequence - 1,
            max: sequence,
            max_at_last_pass: sequence - 1,
            read: [0; WORDS],
            new: true,
        };
        s.mark(sequence);
        s
    }

    fn mark(&mut self, sequence: u64) {
        let bit = sequence % WINDOW;
        self.read[(bit / 64) as usize] |= 1 << (bit % 64);
    }

    /// Whether `sequence` was read; clears its bit for reuse.
    fn take(&mut self, sequence: u64) -> bool {
        let bit = sequence % WINDOW;
        let (word, mask) = ((bit / 64) as usize, 1u64 << (bit % 64));
        let was = self.read[word] & mask != 0;
        self.read[word] &= !mask;
        was
    }
}

/// The gaps in the senders' sequences, and the messages they add up to.
#[derive(Debug, Clone)]
pub struct SequenceGaps {
    senders: [Option<Sender>; SENDERS],
    /// Messages counted as lost so far.
    pub lost: u64,
}

impl Default for SequenceGaps {
    fn default() -> Self {
        SequenceGaps {
            senders: [None; SENDERS],
            lost: 0,
        }
    }
}

impl SequenceGaps {
    /// A message with this (readable) header was read; `accepted`: it passed the checks.
    pub fn read(&mut self, header: &Header, accepted: bool) {
        let (id, sequence) = (header.sender_id, header.sequence);
        if sequence == 0 {
            return;
        }
        let slot = self
            .senders
            .iter()
            .position(|s| s.is_some_and(|s| s.id == id));
        let Some(k) = slot else {
            if accepted && let Some(free) = self.senders.iter_mut().find(|s| s.is_none()) {
                *free = Some(Sender::new(id, sequence));
            }
            return;
        };
        let Some(s) = &mut self.senders[k] else {
            return;
        };
        if sequence <= s.settled {
            return;
        }
        if sequence > s.settled + WINDOW {
            if accepted {
                *s = Sender::new(id, sequence);
            }
            return;
        }
        s.mark(sequence);
        if accepted {
            s.max = s.max.max(sequence);
        }
    }

    /// The end of a drain pass: the holes at or below the previous pass's highest
    /// sequence are counted as lost.
    pub fn end_pass(&mut self) {
        for s in self.senders.iter_mut().flatten() {
            if s.new {
                // Counted from here on: everything up to its highest sequence is settled.
                s.new = false;
                s.settled = s.max;
                s.max_at_last_pass = s.max;
                s.read = [0; WORDS];
                continue;
            }
            for sequence in s.settled + 1..=s.max_at_last_pass {
                if !s.take(sequence) {
                    self.lost += 1;
                }
            }
            s.settled = s.settled.max(s.max_at_last_pass);
            s.max_at_last_pass = s.max;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn h(sender: u32, sequence: u64) -> Header {
        Header::new(sender, sequence, 0)
    }

    /// Reads `sequences` of sender 2 (accepted) in one pass, then ends it.
    fn pass(g: &mut SequenceGaps, sequences: &[u64]) {
        for &s in sequences {
            g.read(&h(2, s), true);
        }
        g.end_pass();
    }

    #[test]
    fn a_hole_counts_one_pass_after_a_later_sequence_was_read() {
        let mut g = SequenceGaps::default();
        pass(&mut g, &[1, 2, 3]);
        // 5 read, 4 not yet: it may still be in a buffer drained earlier in this pass.
        pass(&mut g, &[5]);
        assert_eq!(g.lost, 0);
        // Read in the next pass: not lost.
        pass(&mut g, &[4, 6]);
        assert_eq!(g.lost, 0);
        // 7 and 8 never come; 9 does. They count at the end of the pass after 9's.
        pass(&mut g, &[9]);
        assert_eq!(g.lost, 0);
        pass(&mut g, &[]);
        assert_eq!(g.lost, 2);
        pass(&mut g, &[10]);
        pass(&mut g, &[]);
        assert_eq!(g.lost, 2);
    }

    #[test]
    fn a_rejected_message_fills_its_hole_but_moves_nothing() {
        let mut g = SequenceGaps::default();
        pass(&mut g, &[1]);
        // 2 rejected, read: not lost. A rejected garbage sequence opens no gap.
        g.read(&h(2, 2), false);
        g.read(&h(2, 1_000_000_000_000_000), false);
        pass(&mut g, &[3]);
        pass(&mut g, &[4]);
        pass(&mut g, &[]);
        assert_eq!(g.lost, 0);
    }

    #[test]
    fn senders_count_apart_and_a_jump_starts_afresh() {
        let mut g = SequenceGaps::default();
        for s in [1, 2] {
            g.read(&h(2, s), true);
            g.read(&h(7, s * 2), true);
        }
        g.end_pass();
        // Sender 7 read 2 and 4 in its first drain: 3 is not counted (a restarted
        // planner's first drain mixes old history samples with live ones).
        g.read(&h(7, 6), true);
        g.end_pass();
        g.end_pass();
        // 5 is lost.
        assert_eq!(g.lost, 1);
        // A restart far above: no gap counted for the jump.
        pass(&mut g, &[3 + 2 * WINDOW, 4 + 2 * WINDOW]);
        pass(&mut g, &[]);
        assert_eq!(g.lost, 1);
    }
}
