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
//! A sender is counted from the end of the first drain that reads a live message of it (on
//! a service without history: ownship, lead state, tracks): what it published before the
//! planner's subscribers were there was never this planner's to read (a restarted planner
//! is handed the history services' old samples, thousands of sequences below the live
//! ones). A message whose header cannot be read (another protocol version) leaves its
//! hole: its sequence is unknown, and it counts as lost as well as rejected. Sequences
//! within `2 × WINDOW` of `u64::MAX` are not followed. The sequences of accepted messages advance a sender; a
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
/// Messages of one drain kept until their sender is known (the inputs' buffers and
/// histories hold fewer).
const EARLY: usize = 256;

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
    /// The messages of this drain read before their sender was followed (sender,
    /// sequence, accepted): applied to a sender that its first live message starts in the
    /// same drain.
    early: [(u32, u64, bool); EARLY],
    early_len: usize,
    /// Messages counted as lost so far.
    pub lost: u64,
}

impl Default for SequenceGaps {
    fn default() -> Self {
        SequenceGaps {
            senders: [None; SENDERS],
            early: [(0, 0, false); EARLY],
            early_len: 0,
            lost: 0,
        }
    }
}

impl SequenceGaps {
    /// A message with this (readable) header was read; `accepted`: it passed the checks;
    /// `live`: it came from a service without history (a new subscriber is handed no old
    /// samples there), so a sender is followed from its first live message on.
    pub fn read(&mut self, header: &Header, accepted: bool, live: bool) {
        let (id, sequence) = (header.sender_id, header.sequence);
        // 0 is no sequence; the top of the range is left out, so that no sum here wraps.
        if sequence == 0 || sequence > u64::MAX - 2 * WINDOW {
            return;
        }
        let slot = self
            .senders
            .iter()
            .position(|s| s.is_some_and(|s| s.id == id));
        let Some(k) = slot else {
            if accepted && live {
                if let Some(free) = self.senders.iter_mut().find(|s| s.is_none()) {
                    *free = Some(Sender::new(id, sequence));
                }
            } else if self.early_len < EARLY {
                self.early[self.early_len] = (id, sequence, accepted);
                self.early_len += 1;
            }
            return;
        };
        self.apply(k, sequence, accepted);
    }

    /// A message of followed sender `k` was read.
    fn apply(&mut self, k: usize, sequence: u64, accepted: bool) {
        let Some(s) = &mut self.senders[k] else {
            return;
        };
        if sequence <= s.settled {
            return;
        }
        if sequence > s.settled + WINDOW {
            if accepted {
                *s = Sender::new(s.id, sequence);
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
        // The messages read before their (new) sender was followed, in this drain.
        for e in 0..self.early_len {
            let (id, sequence, accepted) = self.early[e];
            let new = |s: &Option<Sender>| s.is_some_and(|s| s.id == id && s.new);
            if let Some(k) = self.senders.iter().position(new) {
                self.apply(k, sequence, accepted);
            }
        }
        self.early_len = 0;
        for s in self.senders.iter_mut().flatten() {
            if s.new {
                // Counted from here on: everything up to its highest accepted sequence in
                // this drain is settled.
                s.new = false;
                // The bits of the settled sequences are cleared for reuse; those above
                // (a rejected message read in this drain) stay.
                let settle = s.max.min(s.settled + WINDOW);
                for sequence in s.settled + 1..=settle {
                    s.take(sequence);
                }
                s.settled = s.max;
                s.max_at_last_pass = s.max;
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
            g.read(&h(2, s), true, true);
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
        g.read(&h(2, 2), false, true);
        g.read(&h(2, 1_000_000_000_000_000), false, true);
        pass(&mut g, &[3]);
        pass(&mut g, &[4]);
        pass(&mut g, &[]);
        assert_eq!(g.lost, 0);
    }

    #[test]
    fn senders_count_apart_and_a_jump_starts_afresh() {
        let mut g = SequenceGaps::default();
        for s in [1, 2] {
            g.read(&h(2, s), true, true);
            g.read(&h(7, s * 2), true, true);
        }
        g.end_pass();
        // Sender 7 read 2 and 4 in its first drain: 3 is not counted (a restarted
        // planner's first drain mixes old history samples with live ones).
        g.read(&h(7, 6), true, true);
        g.end_pass();
        g.end_pass();
        // 5 is lost.
        assert_eq!(g.lost, 1);
        // A restart far above: no gap counted for the jump.
        pass(&mut g, &[3 + 2 * WINDOW, 4 + 2 * WINDOW]);
        pass(&mut g, &[]);
        assert_eq!(g.lost, 1);
    }

    #[test]
    fn history_samples_start_no_sender_and_the_top_sequences_are_not_followed() {
        let mut g = SequenceGaps::default();
        // In its first drain a sender's messages on history services may come before its
        // first live one, and be newer: they settle it too (3 and 4 are not holes).
        g.read(&h(3, 3), true, false);
        g.read(&h(3, 4), true, false);
        g.read(&h(3, 2), true, true);
        // A rejected message above the highest accepted one in the first drain is read.
        g.read(&h(3, 6), false, true);
        g.end_pass();
        g.read(&h(3, 5), true, true);
        g.read(&h(3, 7), true, true);
        g.end_pass();
        g.end_pass();
        assert_eq!(g.lost, 0);
        // A restarted planner is handed an old tasking (history) before live states.
        g.read(&h(2, 3), true, false);
        g.end_pass();
        pass(&mut g, &[900, 901]);
        pass(&mut g, &[902]);
        pass(&mut g, &[]);
        assert_eq!(g.lost, 0);
        // A sender whose sequence is at the top of the range is not followed (no sum
        // wraps, no endless count).
        let top = u64::MAX;
        g.read(&h(9, top), true, true);
        g.end_pass();
        g.read(&h(9, top), true, true);
        g.end_pass();
        g.end_pass();
        assert_eq!(g.lost, 0);
    }
}
