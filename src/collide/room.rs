//! Room for lists whose length a caller's input sets (self-collision's neighbour lists, a mesh
//! collider's candidates): a bound on their entries, and growth that asks the allocator
//! fallibly. Past the bound, or when the allocator refuses, the push is refused and the caller
//! turns that into an error instead of exhausting memory (or overflowing 32-bit offsets) in
//! the middle of a bake.

/// Room for lists whose length the caller's input sets, in entries: every push counts against
/// it and grows its list fallibly.
#[derive(Debug)]
pub(crate) struct Room {
    left: usize,
    /// Why a push was refused, once one was: nothing more is pushed after it.
    pub(crate) full: Option<Full>,
}

/// Why the room ran out.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Full {
    /// More entries than the room allows.
    Entries,
    /// The allocator refused.
    Memory,
}

impl Room {
    pub(crate) fn new(entries: usize) -> Room {
        Room {
            left: entries,
            full: None,
        }
    }

    /// Pushes `item` onto `list` if there is room; false (and nothing pushed) when not.
    pub(crate) fn push<T>(&mut self, list: &mut Vec<T>, item: T) -> bool {
        if self.full.is_some() {
            return false;
        }
        if self.left == 0 {
            self.full = Some(Full::Entries);
            return false;
        }
        if !make_room(list, 1) {
            self.full = Some(Full::Memory);
            return false;
        }
        self.left -= 1;
        list.push(item);
        true
    }

    /// Gives back the room of `k` entries (a list about to be cleared and filled again).
    pub(crate) fn give_back(&mut self, k: usize) {
        self.left += k;
    }

    /// Entries still to be had.
    pub(crate) fn left(&self) -> usize {
        self.left
    }

    /// Counts `k` entries pushed (their room asked for elsewhere) against the room.
    pub(crate) fn spend(&mut self, k: usize) {
        if k > self.left {
            self.left = 0;
            self.full = Some(Full::Entries);
        } else {
            self.left -= k;
        }
    }
}

/// Room for `k` more entries in `list`, asked of the allocator fallibly (at least doubling, or
/// 64 entries); false when it refuses.
pub(crate) fn make_room<T>(list: &mut Vec<T>, k: usize) -> bool {
    list.capacity() - list.len() >= k || list.try_reserve(list.len().max(64).max(k)).is_ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_room_refuses_past_its_entries_and_keeps_refusing() {
        let mut room = Room::new(3);
        let mut a = Vec::new();
        assert!(room.push(&mut a, 1u32) && room.push(&mut a, 2));
        a.push(3);
        room.spend(1);
        assert_eq!(room.full, None);
        assert!(!room.push(&mut a, 4), "a fourth entry in a room of three");
        assert_eq!(room.full, Some(Full::Entries));
        assert_eq!(a, [1, 2, 3]);
        assert!(!room.push(&mut a, 5), "nothing more once full");
        // Spending more than is left fills it too.
        let mut room = Room::new(2);
        room.spend(3);
        assert_eq!(room.full, Some(Full::Entries));
        // Room given back is room again.
        let mut room = Room::new(1);
        let mut b = vec![7u32];
        room.spend(1);
        room.give_back(b.len());
        b.clear();
        assert!(room.push(&mut b, 8) && room.left() == 0);
    }
}
