//! The reference geometry of every element of a set ([`ElementGeometry`], 2.6 KiB each: 106 MiB
//! for the 40 000 elements of a 200 x 200 mesh), indexed by element, and trimmed to the elements
//! one process evaluates when a model is shared over several ([`Geometries::retain`], see
//! `stamp::share`): the geometry was the largest part of the model every process held whole.

use crate::geometry::ElementGeometry;

/// Per-element geometry, `geometries[e]`; after [`retain`](Geometries::retain) only the kept
/// elements' (indexing another is a bug: it panics, naming the element).
#[derive(Debug, Clone)]
pub struct Geometries {
    list: Vec<ElementGeometry>,
    /// After a retain: the position in `list` of each element's geometry, u32::MAX if dropped.
    slot: Option<Vec<u32>>,
}

impl Geometries {
    /// Every element's geometry, element e at position e.
    pub fn new(list: Vec<ElementGeometry>) -> Self {
        Geometries { list, slot: None }
    }

    /// Keep the geometry of the elements flagged in `keep` (one flag per element) and free the
    /// others'. Elements dropped before stay dropped.
    pub fn retain(&mut self, keep: &[bool]) {
        let n = self.slot.as_ref().map_or(self.list.len(), Vec::len);
        let mut slot = vec![u32::MAX; n];
        let mut list = Vec::with_capacity(keep.iter().filter(|k| **k).count());
        for e in (0..n).filter(|&e| keep.get(e).copied().unwrap_or(false)) {
            if let Some(g) = self.get(e) {
                slot[e] = list.len() as u32;
                list.push(*g);
            }
        }
        self.list = list;
        self.slot = Some(slot);
    }

    /// Element e's geometry, if it was kept.
    pub fn get(&self, e: usize) -> Option<&ElementGeometry> {
        match &self.slot {
            None => self.list.get(e),
            Some(slot) => slot.get(e).filter(|&&s| s != u32::MAX).map(|&s| &self.list[s as usize]),
        }
    }

    /// The geometries held (all of them, or the kept ones).
    pub fn held(&self) -> usize {
        self.list.len()
    }
}

impl std::ops::Index<usize> for Geometries {
    type Output = ElementGeometry;
    fn index(&self, e: usize) -> &ElementGeometry {
        self.get(e).unwrap_or_else(|| panic!("element {e}'s geometry is not held by this process (it evaluates other elements, see Element::retain_elements)"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(side: f64, label: usize) -> ElementGeometry {
        ElementGeometry::new(&[[0.0, 0.0], [side, 0.0], [side, side], [0.0, side]], label).unwrap()
    }

    /// The kept elements keep their own geometry (told apart by their areas), a second retain
    /// narrows the first, and a dropped element is refused.
    #[test]
    fn retain_keeps_the_flagged_elements_geometry() {
        let all: Vec<ElementGeometry> = (0..5).map(|e| square(1.0 + e as f64, e)).collect();
        let mut g = Geometries::new(all.clone());
        assert_eq!(g.held(), 5);
        g.retain(&[true, false, true, true, false]);
        assert_eq!(g.held(), 3);
        for e in [0, 2, 3] {
            assert_eq!(g[e].area, all[e].area);
            assert_eq!(g[e].wdet, all[e].wdet);
        }
        assert!(g.get(1).is_none() && g.get(4).is_none() && g.get(9).is_none());
        g.retain(&[true, true, false, true, true]);
        assert_eq!(g.held(), 2);
        assert!(g.get(1).is_none() && g.get(2).is_none());
        assert_eq!((g[0].area, g[3].area), (all[0].area, all[3].area));
        let dropped = std::panic::catch_unwind(|| g[2].area).unwrap_err();
        assert!(dropped.downcast_ref::<String>().is_some_and(|m| m.contains("element 2")));
    }
}
