//! Who may hold a connection: the slot policy that keeps slow or idle
//! strangers from locking out the person who holds the session token.
//!
//! Every new connection starts in the *open* pool. As soon as its request
//! line shows the token, it moves to the *trusted* pool, which strangers
//! cannot enter. When the open pool is full, a newcomer takes the slot of
//! the oldest open connection, which is closed: a client that trickles its
//! request can hold a slot only until enough others arrive, and a person
//! whose request arrives at once (milliseconds) is never the oldest.

use std::net::TcpStream;
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::{Duration, Instant};

/// How long the accept loop waits for an evicted connection's thread to
/// let go of its slot before refusing the newcomer.
const EVICTION_WAIT: Duration = Duration::from_secs(1);

/// How many connections each pool holds now.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Occupancy {
    /// Connections that have not (yet) shown the token.
    pub open: usize,
    /// Connections whose request line carried the token.
    pub trusted: usize,
}

struct OpenEntry {
    id: u64,
    since: Instant,
    /// A handle on the socket, to close it when evicted.
    stream: TcpStream,
    evicted: bool,
}

#[derive(Default)]
struct Pools {
    open: Vec<OpenEntry>,
    trusted: usize,
    next_id: u64,
}

/// The two pools and their sizes.
pub(super) struct Slots {
    open_max: usize,
    trusted_max: usize,
    pools: Mutex<Pools>,
    freed: Condvar,
}

/// A held slot, given back on drop (also when a handler panics).
pub(super) struct Ticket {
    slots: Arc<Slots>,
    id: u64,
    trusted: bool,
}

impl Slots {
    pub(super) fn new(open_max: usize, trusted_max: usize) -> Arc<Self> {
        Arc::new(Self {
            open_max,
            trusted_max,
            pools: Mutex::new(Pools::default()),
            freed: Condvar::new(),
        })
    }

    fn lock(&self) -> MutexGuard<'_, Pools> {
        // The pools are consistent between statements; a panic elsewhere
        // while holding the lock cannot leave them half-updated.
        self.pools.lock().unwrap_or_else(|p| p.into_inner())
    }

    pub(super) fn occupancy(&self) -> Occupancy {
        let pools = self.lock();
        Occupancy {
            open: pools.open.len(),
            trusted: pools.trusted,
        }
    }

    /// Gives `stream` a slot in the open pool, evicting the oldest open
    /// connection if the pool is full. `None` if no slot came free (the
    /// evicted thread did not finish in time, or the socket cannot be
    /// shared).
    pub(super) fn admit(self: &Arc<Self>, stream: &TcpStream) -> Option<Ticket> {
        let handle = stream.try_clone().ok()?;
        let mut pools = self.lock();
        let give_up = Instant::now() + EVICTION_WAIT;
        while pools.open.len() >= self.open_max {
            if !pools.open.iter().any(|e| e.evicted) {
                let oldest = pools
                    .open
                    .iter_mut()
                    .filter(|e| !e.evicted)
                    .min_by_key(|e| e.since)?;
                oldest.evicted = true;
                // Wakes its thread from any read or write; it then ends
                // and gives the slot back.
                let _ = oldest.stream.shutdown(std::net::Shutdown::Both);
            }
            let now = Instant::now();
            if now >= give_up {
                return None;
            }
            pools = self
                .freed
                .wait_timeout(pools, give_up - now)
                .unwrap_or_else(|p| p.into_inner())
                .0;
        }
        let id = pools.next_id;
        pools.next_id += 1;
        pools.open.push(OpenEntry {
            id,
            since: Instant::now(),
            stream: handle,
            evicted: false,
        });
        Some(Ticket {
            slots: self.clone(),
            id,
            trusted: false,
        })
    }

    /// Moves `ticket` to the trusted pool; false if that pool is full or
    /// the connection was evicted meanwhile (the ticket stays as it was).
    pub(super) fn promote(&self, ticket: &mut Ticket) -> bool {
        if ticket.trusted {
            return true;
        }
        let mut pools = self.lock();
        let Some(i) = pools.open.iter().position(|e| e.id == ticket.id) else {
            return false;
        };
        if pools.open[i].evicted || pools.trusted >= self.trusted_max {
            return false;
        }
        pools.open.swap_remove(i);
        pools.trusted += 1;
        ticket.trusted = true;
        self.freed.notify_all();
        true
    }
}

impl Ticket {
    /// Moves this connection to the trusted pool (see [`Slots::promote`]).
    pub(super) fn promote(&mut self) -> bool {
        let slots = self.slots.clone();
        slots.promote(self)
    }
}

impl Drop for Ticket {
    fn drop(&mut self) {
        let mut pools = self.slots.lock();
        if self.trusted {
            pools.trusted -= 1;
        } else if let Some(i) = pools.open.iter().position(|e| e.id == self.id) {
            pools.open.swap_remove(i);
        }
        self.slots.freed.notify_all();
    }
}
