//! The SAH-optimal BVH2 → BVH8 collapse plan.

use super::*;

/// SAH cost of testing one wide node (its eight boxes) per unit of the ray's hit probability.
const NODE_COST: f32 = 1.0;
/// SAH cost of testing one leaf packet (eight triangles in one SIMD test).
const LEAF_COST: f32 = 1.0;

/// Which BVH2 subtrees become wide nodes and which leaf packets: the SAH-optimal collapse of
/// Ylitie, Karras & Laine 2017 ("Efficient incoherent ray traversal on GPUs through compressed
/// wide BVHs", §3.2), a dynamic programme over the BVH2 bottom-up. `cost[n][i − 1]` is the
/// least SAH cost (surface area × test cost, Goldsmith & Salmon 1987; MacDonald & Booth 1990)
/// of the subtree of BVH2 node n as a forest of at most i roots, each a leaf packet of at most
/// `PACKET` triangles or a wide node whose up to eight children are such a forest of its own.
/// The greedy collapse it replaces (open the child of largest area until eight) left 38 % of
/// the wide nodes with two children.
pub(super) struct CollapsePlan {
    cost: Vec<[f32; WIDTH]>,
    /// For `cost[n][i − 1]`: roots taken from n's (left, right) BVH2 children, or (0, 0) when n
    /// itself is the one root.
    split: Vec<[(u8, u8); WIDTH]>,
    /// n's forest of at most eight roots with at least two (its children as a wide node).
    wide: Vec<(u8, u8)>,
    /// Whether n as a single root is a leaf packet (else a wide node).
    pub(super) leaf: Vec<bool>,
}

impl CollapsePlan {
    pub(super) fn new(bvh2: &Bvh2) -> Self {
        let len = bvh2.nodes.len();
        let mut plan = CollapsePlan {
            cost: vec![[f32::INFINITY; WIDTH]; len],
            split: vec![[(0, 0); WIDTH]; len],
            wide: vec![(0, 0); len],
            leaf: vec![false; len],
        };
        let mut counts = vec![0u32; len];
        // Iterative post-order, so that deep trees cannot overflow the call stack.
        let mut stack = vec![(0usize, false)];
        while let Some((n, children_done)) = stack.pop() {
            let node = &bvh2.nodes[n];
            let f = node.first_index as usize;
            if node.prim_count == 0 && !children_done {
                stack.extend([(n, true), (f, false), (f + 1, false)]);
                continue;
            }
            let area = node.aabb().half_area();
            counts[n] = if node.prim_count != 0 {
                node.prim_count
            } else {
                counts[f] + counts[f + 1]
            };
            let leaf_cost = if counts[n] as usize <= PACKET {
                area * LEAF_COST
            } else {
                f32::INFINITY
            };
            if node.prim_count != 0 {
                plan.cost[n] = [leaf_cost; WIDTH];
                plan.leaf[n] = true;
                continue;
            }
            plan.plan_inner(n, f, area, leaf_cost);
        }
        plan
    }

    /// Fills the tables of inner BVH2 node `n` (children `f`, `f + 1`, already planned).
    fn plan_inner(&mut self, n: usize, f: usize, area: f32, leaf_cost: f32) {
        // best[i − 1]: cheapest way to give the two children at most i roots in all (i ≥ 2).
        let mut best = [(f32::INFINITY, (0u8, 0u8)); WIDTH];
        for i in 2..=WIDTH {
            best[i - 1] = best[i - 2];
            for left in 1..i {
                let c = self.cost[f][left - 1] + self.cost[f + 1][i - left - 1];
                if c < best[i - 1].0 {
                    best[i - 1] = (c, (left as u8, (i - left) as u8));
                }
            }
        }
        let (children_cost, wide) = best[WIDTH - 1];
        let node_cost = area * NODE_COST + children_cost;
        self.wide[n] = wide;
        self.leaf[n] = leaf_cost <= node_cost;
        self.cost[n][0] = leaf_cost.min(node_cost);
        for i in 2..=WIDTH {
            let (c, s) = best[i - 1];
            (self.cost[n][i - 1], self.split[n][i - 1]) = if c < self.cost[n][i - 2] {
                (c, s)
            } else {
                (self.cost[n][i - 2], self.split[n][i - 2])
            };
        }
    }

    /// The children of BVH2 node `n` made a wide node (2 to 8 BVH2 nodes).
    /// The wide nodes and leaf packets the collapse makes (walked as [`WideBvh::from_bvh2`]
    /// walks it), so that both are allocated once at their size: grown by doubling, up to half
    /// of each was unused and the last doubling of the packets needed their size again, which
    /// failed under a tight `ulimit -v` after the memory estimate had passed.
    pub(super) fn sizes(&self, bvh2: &Bvh2) -> (usize, usize) {
        if self.leaf[0] {
            return (0, 1);
        }
        let (mut nodes, mut packets) = (1, 0);
        let (mut pending, mut kids) = (vec![0usize], Vec::with_capacity(WIDTH));
        while let Some(n2) = pending.pop() {
            kids.clear();
            self.wide_children(bvh2, n2, &mut kids);
            for &k in &kids {
                if self.leaf[k] {
                    packets += 1;
                } else {
                    nodes += 1;
                    pending.push(k);
                }
            }
        }
        (nodes, packets)
    }

    pub(super) fn wide_children(&self, bvh2: &Bvh2, n: usize, out: &mut Vec<usize>) {
        let f = bvh2.nodes[n].first_index as usize;
        let (left, right) = self.wide[n];
        self.roots(bvh2, f, left as usize, out);
        self.roots(bvh2, f + 1, right as usize, out);
    }

    /// The roots of BVH2 node `n`'s forest of at most `i` roots.
    fn roots(&self, bvh2: &Bvh2, n: usize, i: usize, out: &mut Vec<usize>) {
        match self.split[n][i - 1] {
            (0, 0) => out.push(n),
            (left, right) => {
                let f = bvh2.nodes[n].first_index as usize;
                self.roots(bvh2, f, left as usize, out);
                self.roots(bvh2, f + 1, right as usize, out);
            }
        }
    }
}
