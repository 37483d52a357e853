//! Counts keyed by a small fixed set (the levels of detail, the obstacles): typed inside the
//! program, printed by name in the summary and its JSON.

use serde::ser::{Serialize, SerializeMap, Serializer};
use std::marker::PhantomData;
use std::ops::{Index, IndexMut};

use super::Obstacle;
use crate::contract::Lod;

/// A key of a fixed set of three, with the name the summary prints for it.
pub trait Key: Copy + 'static {
    /// Every key, in the summary's order.
    const ALL: [Self; 3];
    /// The name the summary prints.
    fn name(self) -> &'static str;
    /// Its place in `ALL`.
    fn index(self) -> usize;
}

impl Key for Lod {
    const ALL: [Self; 3] = Lod::ALL;
    fn name(self) -> &'static str {
        Lod::name(self)
    }
    fn index(self) -> usize {
        self as usize
    }
}

impl Key for Obstacle {
    const ALL: [Self; 3] = Obstacle::ALL;
    fn name(self) -> &'static str {
        Obstacle::name(self)
    }
    fn index(self) -> usize {
        self as usize
    }
}

/// One value for each key.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Counts<K, T> {
    values: [T; 3],
    key: PhantomData<K>,
}

impl<K, T: Default + Copy> Default for Counts<K, T> {
    fn default() -> Self {
        Self {
            values: [T::default(); 3],
            key: PhantomData,
        }
    }
}

impl<K: Key, T: Copy> Counts<K, T> {
    /// The value of each key, from `f`.
    pub fn from_fn(mut f: impl FnMut(K) -> T) -> Self {
        Self {
            values: K::ALL.map(&mut f),
            key: PhantomData,
        }
    }

    /// Each key with its value, in the keys' order.
    pub fn iter(&self) -> impl Iterator<Item = (K, T)> + '_ {
        K::ALL.into_iter().zip(self.values)
    }
}

impl<K: Key, T> Index<K> for Counts<K, T> {
    type Output = T;
    fn index(&self, key: K) -> &T {
        &self.values[key.index()]
    }
}

impl<K: Key, T> IndexMut<K> for Counts<K, T> {
    fn index_mut(&mut self, key: K) -> &mut T {
        &mut self.values[key.index()]
    }
}

impl<K: Key, T: Serialize> Serialize for Counts<K, T> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(Some(3))?;
        for (key, value) in K::ALL.iter().zip(&self.values) {
            map.serialize_entry(key.name(), value)?;
        }
        map.end()
    }
}

/// Level switches by where they came from and went to.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SwitchCounts(pub Counts<Lod, Counts<Lod, u64>>);

impl SwitchCounts {
    /// Every switch.
    pub fn total(&self) -> u64 {
        self.0.values.iter().flat_map(|to| to.values).sum()
    }

    /// Switches from `from` to `to`.
    pub fn between(&self, from: Lod, to: Lod) -> u64 {
        self.0[from][to]
    }

    /// Counts one switch from `from` to `to`.
    pub fn count(&mut self, from: Lod, to: Lod) {
        self.0[from][to] += 1;
    }

    /// The directions that happened, with their counts.
    pub fn directions(&self) -> impl Iterator<Item = (Lod, Lod, u64)> + '_ {
        Lod::ALL
            .into_iter()
            .flat_map(|from| Lod::ALL.into_iter().map(move |to| (from, to)))
            .map(|(from, to)| (from, to, self.0[from][to]))
            .filter(|&(_, _, n)| n > 0)
    }
}

/// As the summary prints it: `total`, then `"from->to"` for each direction that happened.
impl Serialize for SwitchCounts {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(None)?;
        map.serialize_entry("total", &self.total())?;
        for (from, to, n) in self.directions() {
            map.serialize_entry(&format!("{}->{}", from.name(), to.name()), &n)?;
        }
        map.end()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_print_by_name_and_switches_by_direction() {
        let mut levels: Counts<Lod, u64> = Counts::default();
        levels[Lod::Rigid] = 4;
        let json = serde_json::to_string(&levels).unwrap();
        assert_eq!(json, r#"{"point_mass":0,"hybrid":0,"rigid":4}"#);
        let mut switches = SwitchCounts::default();
        switches.count(Lod::Hybrid, Lod::Rigid);
        switches.count(Lod::Hybrid, Lod::Rigid);
        switches.count(Lod::Rigid, Lod::PointMass);
        assert_eq!(switches.total(), 3);
        assert_eq!(
            serde_json::to_string(&switches).unwrap(),
            r#"{"total":3,"hybrid->rigid":2,"rigid->point_mass":1}"#
        );
    }
}
