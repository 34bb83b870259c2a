//! AF1's queue: a 4-ary min-heap of `u64` entries.
//!
//! Half the depth of a binary heap: a pop's sift is a chain of cache
//! misses once the heap outgrows the cache (millions of entries at 1e6
//! tets, the dead faces' among them), and four children share a line.
//! Entries are distinct, so the pop order is that of any min-heap.

#[derive(Clone, Debug, Default)]
pub(crate) struct MinQueue {
    a: Vec<u64>,
}

impl MinQueue {
    pub(crate) fn push(&mut self, x: u64) {
        let mut i = self.a.len();
        self.a.push(x);
        while i > 0 {
            let p = (i - 1) / 4;
            if self.a[p] <= x {
                break;
            }
            self.a[i] = self.a[p];
            i = p;
        }
        self.a[i] = x;
    }

    pub(crate) fn pop(&mut self) -> Option<u64> {
        let last = self.a.pop()?;
        let n = self.a.len();
        if n == 0 {
            return Some(last);
        }
        let top = self.a[0];
        // Sift `last` down from the root.
        let mut i = 0;
        loop {
            let c = 4 * i + 1;
            if c >= n {
                break;
            }
            let end = (c + 4).min(n);
            let mut m = c;
            for j in c + 1..end {
                if self.a[j] < self.a[m] {
                    m = j;
                }
            }
            if self.a[m] >= last {
                break;
            }
            self.a[i] = self.a[m];
            i = m;
        }
        self.a[i] = last;
        Some(top)
    }

    pub(crate) fn clear(&mut self) {
        self.a.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pops_in_order() {
        let mut q = MinQueue::default();
        let mut s = 99u64;
        let mut all = Vec::new();
        for round in 0..20 {
            for _ in 0..(50 + round * 7) {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let x = s >> 20;
                q.push(x);
                all.push(x);
            }
            all.sort_unstable_by(|a, b| b.cmp(a));
            for _ in 0..30 {
                assert_eq!(q.pop(), all.pop());
            }
        }
        while let Some(x) = all.pop() {
            assert_eq!(q.pop(), Some(x));
        }
        assert_eq!(q.pop(), None);
    }
}
