//! The streaming contact sampler: fed the contact list every `n` steps, it closes rows as
//! they complete (`Δt_c^max` reached, contact opened, or the period ends) and releases them
//! in apparition order. Memory follows the open contacts, not the table.

use super::CollisionRow;
use rustc_hash::FxHashMap;
use std::collections::VecDeque;

/// A contact seen at the previous sample, with its row in progress.
#[derive(Debug, Clone, Copy, serde::Serialize, serde::Deserialize)]
struct OpenContact {
    row_start: u64,
    samples: u32,
    sqrt_area_sum: f64,
    /// Apparition rank of the row in progress (meaningful while `samples > 0`).
    seq: u64,
    last_seen: u64,
    /// Samples of the whole collision so far (across its rows).
    collision_samples: u32,
}

/// Rows by apparition rank, from the oldest not yet released: `None` while in progress.
/// Spans at most the rows started within `Δt_c^max`, since no row stays open longer.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
struct RowWindow {
    /// Rank of `slots[0]`.
    base: u64,
    slots: VecDeque<Option<CollisionRow>>,
}

impl RowWindow {
    /// Reserves the next rank for a row that has just started.
    fn start(&mut self) -> u64 {
        self.slots.push_back(None);
        self.base + self.slots.len() as u64 - 1
    }

    fn complete(&mut self, seq: u64, row: CollisionRow) {
        self.slots[(seq - self.base) as usize] = Some(row);
    }

    /// Releases the leading completed rows.
    fn drain_completed(&mut self) -> Vec<CollisionRow> {
        let ready = self.slots.iter().take_while(|s| s.is_some()).count();
        self.base += ready as u64;
        self.slots
            .drain(..ready)
            .map(|s| s.expect("completed"))
            .collect()
    }
}

impl OpenContact {
    /// Ends the row in progress (if it has samples) into its slot of the window.
    fn close_row(&mut self, key: (u32, u32), every: u32, done: &mut RowWindow) {
        if self.samples > 0 {
            let row = CollisionRow {
                i: key.0,
                j: key.1,
                start_step: self.row_start,
                duration_steps: self.samples * every,
                sqrt_area: self.sqrt_area_sum / self.samples as f64,
            };
            done.complete(self.seq, row);
            self.samples = 0;
            self.sqrt_area_sum = 0.0;
        }
    }
}

/// Builds the collision table of one period from samples of the DEM contact list.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct ContactSampler {
    /// Sampling factor `n` (steps per sample).
    pub every: u32,
    /// `Δt_c^max` in steps, a multiple of `n`.
    pub max_duration: u32,
    /// Open contacts by pair; Fx hashing because the map is probed once per contact per sample.
    open: FxHashMap<(u32, u32), OpenContact>,
    /// Rows not yet released, in apparition order.
    done: RowWindow,
    /// Step of the last sample, if any.
    last_sample: Option<u64>,
    /// `histogram[s]`: ended collisions seen at `s` consecutive samples.
    histogram: Vec<u64>,
}

impl ContactSampler {
    /// `None` unless `every > 0` and `max_duration` is a positive multiple of `every`.
    pub fn new(every: u32, max_duration: u32) -> Option<Self> {
        if every == 0 || max_duration == 0 || !max_duration.is_multiple_of(every) {
            return None;
        }
        Some(Self {
            every,
            max_duration,
            open: FxHashMap::default(),
            done: RowWindow::default(),
            last_sample: None,
            histogram: Vec::new(),
        })
    }

    /// Checks a sampler read back from a checkpoint, in a period of `max_samples` samples:
    /// every row in progress has its slot in the window of unreleased rows, no slot is
    /// claimed twice, and no count exceeds what the period allows (the histogram grows to
    /// the longest collision).
    pub fn check(&self, max_samples: u64) -> Result<(), String> {
        let row_samples = (self.max_duration / self.every.max(1)) as u64;
        if let Some((key, c)) = self.open.iter().find(|(_, c)| {
            c.collision_samples as u64 > max_samples || c.samples as u64 > row_samples
        }) {
            return Err(format!(
                "open contact {key:?} counts {} samples ({} in its row); the period has {max_samples}, a row at most {row_samples}",
                c.collision_samples, c.samples
            ));
        }
        if self.histogram.len() as u64 > max_samples + 1 {
            return Err(format!(
                "a histogram of {} collision lengths exceeds a period of {max_samples} samples",
                self.histogram.len()
            ));
        }
        let mut claimed = vec![false; self.done.slots.len()];
        for (key, c) in &self.open {
            if c.samples == 0 {
                continue;
            }
            let slot = c.seq.checked_sub(self.done.base).map(|s| s as usize);
            match slot.filter(|&s| s < claimed.len() && self.done.slots[s].is_none()) {
                Some(s) if !claimed[s] => claimed[s] = true,
                _ => {
                    return Err(format!(
                        "open contact {key:?} has row rank {} outside the unreleased rows {}..{}",
                        c.seq,
                        self.done.base,
                        self.done.base + claimed.len() as u64
                    ))
                }
            }
        }
        let waiting = self.done.slots.iter().filter(|s| s.is_none()).count();
        let in_progress = claimed.iter().filter(|&&c| c).count();
        if waiting != in_progress {
            return Err(format!(
                "{waiting} rows wait for {in_progress} contacts in progress"
            ));
        }
        Ok(())
    }

    /// Number of contacts currently open.
    pub fn open_contacts(&self) -> usize {
        self.open.len()
    }

    /// Records the contacts touching at `step`, in the order the DEM lists them; each pair
    /// once, as `(id_a, id_b, sqrt(area))`. Steps must advance by `every`.
    pub fn sample(&mut self, step: u64, contacts: impl IntoIterator<Item = (u32, u32, f64)>) {
        debug_assert!(self
            .last_sample
            .is_none_or(|s| step == s + self.every as u64));
        let full_row = self.max_duration / self.every;
        for (a, b, sqrt_area) in contacts {
            let key = (a.min(b), a.max(b));
            let c = self.open.entry(key).or_insert_with(|| OpenContact {
                row_start: step,
                samples: 0,
                sqrt_area_sum: 0.0,
                seq: 0,
                last_seen: step,
                collision_samples: 0,
            });
            if c.samples == 0 {
                c.row_start = step;
                c.seq = self.done.start();
            }
            c.samples += 1;
            c.collision_samples += 1;
            c.sqrt_area_sum += sqrt_area;
            c.last_seen = step;
            if c.samples == full_row {
                c.close_row(key, self.every, &mut self.done);
            }
        }
        // contacts not seen at this sample have opened: their last row ends here
        let (every, done, histogram) = (self.every, &mut self.done, &mut self.histogram);
        self.open.retain(|&key, c| {
            let open = c.last_seen == step;
            if !open {
                c.close_row(key, every, done);
                count(histogram, c.collision_samples);
            }
            open
        });
        self.last_sample = Some(step);
    }

    /// Ended collisions by length in samples (`[s]`: seen at `s` consecutive samples); after
    /// [`Self::finish`] it includes the collisions cut at the end of the period.
    pub fn duration_histogram(&self) -> &[u64] {
        &self.histogram
    }

    /// Rows that can no longer be preceded by another, in apparition order.
    pub fn drain_ready(&mut self) -> Vec<CollisionRow> {
        self.done.drain_completed()
    }

    /// Ends the period: contacts still open are cut, and every remaining row is returned.
    pub fn finish(&mut self) -> Vec<CollisionRow> {
        for (key, mut c) in self.open.drain() {
            c.close_row(key, self.every, &mut self.done);
            count(&mut self.histogram, c.collision_samples);
        }
        let rows = self.done.drain_completed();
        debug_assert!(self.done.slots.is_empty());
        rows
    }
}

fn count(histogram: &mut Vec<u64>, samples: u32) {
    let s = samples as usize;
    if histogram.len() <= s {
        histogram.resize(s + 1, 0);
    }
    histogram[s] += 1;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Feeds `present(sample_index)` contacts for `samples` samples and returns all rows.
    fn run(
        every: u32,
        max: u32,
        samples: u64,
        present: impl Fn(u64) -> Vec<(u32, u32, f64)>,
    ) -> Vec<CollisionRow> {
        let mut s = ContactSampler::new(every, max).unwrap();
        let mut rows = Vec::new();
        for k in 0..samples {
            s.sample(k * every as u64, present(k));
            rows.extend(s.drain_ready());
        }
        rows.extend(s.finish());
        rows
    }

    #[test]
    fn a_25_step_collision_splits_as_in_table_1() {
        // n = 1: contact during samples 3..28 (25 steps)
        let contact = |k: u64| {
            if (3..28).contains(&k) {
                vec![(4, 9, 1e-3)]
            } else {
                vec![]
            }
        };
        let rows = run(1, 10, 40, contact);
        let spans: Vec<(u64, u32)> = rows
            .iter()
            .map(|r| (r.start_step, r.duration_steps))
            .collect();
        assert_eq!(spans, vec![(3, 10), (13, 10), (23, 5)]);
        let rows = run(1, 20, 40, contact);
        let spans: Vec<(u64, u32)> = rows
            .iter()
            .map(|r| (r.start_step, r.duration_steps))
            .collect();
        assert_eq!(spans, vec![(3, 20), (23, 5)]);
        assert!(rows
            .iter()
            .all(|r| (r.i, r.j) == (4, 9) && (r.sqrt_area / 1e-3 - 1.0).abs() < 1e-14));
    }

    #[test]
    fn sampling_factor_scales_durations() {
        // n = 5, Δt_c^max = 10 steps: 5 samples = 25 steps → 10 + 10 + 5
        let rows = run(5, 10, 12, |k| {
            if (2..7).contains(&k) {
                vec![(1, 2, 1.0)]
            } else {
                vec![]
            }
        });
        let spans: Vec<(u64, u32)> = rows
            .iter()
            .map(|r| (r.start_step, r.duration_steps))
            .collect();
        assert_eq!(spans, vec![(10, 10), (20, 10), (30, 5)]);
    }

    #[test]
    fn contacts_open_at_t0_start_at_t0_and_open_at_t1_are_cut() {
        let rows = run(1, 100, 10, |_| vec![(0, 1, 2.0)]);
        assert_eq!(rows.len(), 1);
        assert_eq!((rows[0].start_step, rows[0].duration_steps), (0, 10));
    }

    #[test]
    fn rows_come_out_in_apparition_order_and_average_the_area() {
        // pair A starts at 0 and lasts long; pair B starts at 1, ends at 3; C starts at 1 after B
        let rows = run(1, 4, 8, |k| {
            let mut c = vec![(0, 1, k as f64)];
            if (1..3).contains(&k) {
                c.push((5, 2, 1.0));
            }
            if k == 1 {
                c.push((7, 8, 3.0));
            }
            c
        });
        let order: Vec<(u32, u32, u64)> = rows.iter().map(|r| (r.i, r.j, r.start_step)).collect();
        assert_eq!(order, vec![(0, 1, 0), (2, 5, 1), (7, 8, 1), (0, 1, 4)]);
        assert_eq!(rows[0].sqrt_area, (0.0 + 1.0 + 2.0 + 3.0) / 4.0);
        let starts: Vec<u64> = rows.iter().map(|r| r.start_step).collect();
        assert!(starts.windows(2).all(|w| w[0] <= w[1]));
    }

    #[test]
    fn streaming_rows_equal_algorithm_2_on_random_contact_patterns() {
        use crate::record::splitter::split;
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut coin = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            !(state >> 33).is_multiple_of(4)
        };
        for (every, max) in [(1u32, 10u32), (2, 10), (5, 20), (10, 100)] {
            let samples = 300u64;
            // 6 pairs, each present at a sample with probability 3/4
            let present: Vec<Vec<bool>> = (0..6)
                .map(|_| (0..samples).map(|_| coin()).collect())
                .collect();
            let rows = run(every, max, samples, |k| {
                (0..6u32)
                    .filter(|&p| present[p as usize][k as usize])
                    .map(|p| (p, p + 10, 1.0))
                    .collect()
            });
            let mut expected = Vec::new();
            for (p, seen) in present.iter().enumerate() {
                let mut k = 0;
                while k < samples as usize {
                    if seen[k] {
                        let first = k;
                        while k < samples as usize && seen[k] {
                            k += 1;
                        }
                        let (start, len) = (
                            first as u64 * every as u64,
                            (k - first) as u64 * every as u64,
                        );
                        expected.extend(
                            split(start, len, max as u64)
                                .into_iter()
                                .map(|r| (r.0, p as u32, r.1 as u32)),
                        );
                    } else {
                        k += 1;
                    }
                }
            }
            expected.sort();
            let got: Vec<(u64, u32, u32)> = rows
                .iter()
                .map(|r| (r.start_step, r.i, r.duration_steps))
                .collect();
            assert!(
                got.windows(2).all(|w| w[0].0 <= w[1].0),
                "not in apparition order"
            );
            let mut sorted = got.clone();
            sorted.sort();
            assert_eq!(sorted, expected, "n = {every}, max = {max}");
        }
    }

    #[test]
    fn the_histogram_counts_whole_collisions_before_splitting() {
        let mut s = ContactSampler::new(1, 10).unwrap();
        // pair (1,2): 25 samples (3 rows); pair (3,4): 2 samples, twice
        for k in 0..30u64 {
            let mut c = Vec::new();
            if k < 25 {
                c.push((1, 2, 1.0));
            }
            if k < 2 || (5..7).contains(&k) {
                c.push((3, 4, 1.0));
            }
            s.sample(k, c);
        }
        let rows = s.finish();
        assert_eq!(rows.len(), 3 + 2);
        let h = s.duration_histogram();
        assert_eq!(h.len(), 26);
        assert_eq!((h[2], h[25], h.iter().sum::<u64>()), (2, 1, 3));
    }

    #[test]
    fn invalid_settings_are_refused() {
        assert!(ContactSampler::new(0, 10).is_none());
        assert!(ContactSampler::new(3, 10).is_none());
        assert!(ContactSampler::new(5, 0).is_none());
    }
}
