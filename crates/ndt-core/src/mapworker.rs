//! The odometry loop's mapper (the §V elimination in front of its own grid),
//! updated in line or on a helper thread behind the loop.
//!
//! The loop's poses do not depend on the mapper (unless it matches against
//! the filtered map), so its updates can run while the loop matches the next
//! scans: each insertion and removal is queued, in order, to one helper
//! thread, and reading the mapper waits until the queue is empty. The mapper
//! is then the same, bit for bit, as one updated in line.
//!
//! A queued insertion cannot fail: it is checked first, on the caller's
//! thread, against an empty mapper with the same options and cell size (the
//! checks of [`Mapper::insert_scan`] depend on nothing else), so a scan the
//! mapper would refuse is refused before anything changes.

use std::fmt;
use std::ops::Deref;
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::thread::JoinHandle;

use crate::error::{NdtError, Result};
use crate::key::CellKey;
use crate::mapper::Mapper;
use crate::se2::Pose2;

/// Jobs queued before the loop waits for the helper (bounds its lag and the
/// copies of scans it holds).
const QUEUE_LENGTH: usize = 4;

/// One change to the mapper, in loop order.
enum Job {
    Insert {
        ranges: Vec<f64>,
        angles: Vec<f64>,
        pose: Pose2,
    },
    Remove(Vec<CellKey>),
}

/// What the loop and the helper share.
struct Shared {
    mapper: Mutex<Mapper>,
    state: Mutex<Progress>,
    idle: Condvar,
}

/// Jobs sent and not yet done, and the first error a job gave.
#[derive(Default)]
struct Progress {
    pending: usize,
    error: Option<NdtError>,
}

/// Marks a job done when dropped, also when the job unwinds, so a reader
/// never waits for a job that will not finish.
struct Done<'a> {
    shared: &'a Shared,
    result: Result<()>,
}

impl Drop for Done<'_> {
    fn drop(&mut self) {
        let mut progress = lock(&self.shared.state);
        progress.pending = progress.pending.saturating_sub(1);
        if let Err(e) = std::mem::replace(&mut self.result, Ok(())) {
            progress.error.get_or_insert(e);
        }
        if progress.pending == 0 {
            self.shared.idle.notify_all();
        }
    }
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// The helper thread: runs the jobs in order until the loop hangs up.
fn serve(shared: &Shared, jobs: Receiver<Job>) {
    for job in jobs {
        let mut done = Done {
            shared,
            result: Ok(()),
        };
        let mut mapper = lock(&shared.mapper);
        done.result = match job {
            Job::Insert {
                ranges,
                angles,
                pose,
            } => mapper.insert_scan(&ranges, &angles, pose),
            Job::Remove(keys) => {
                mapper.remove_cells(&keys);
                Ok(())
            }
        };
        // The mapper is unlocked before the job counts as done.
        drop(mapper);
    }
}

/// The mapper updated on a helper thread.
pub(crate) struct Behind {
    shared: Arc<Shared>,
    /// An empty mapper with the same options and cell size: checks scans.
    checker: Mapper,
    jobs: Option<SyncSender<Job>>,
    thread: Option<JoinHandle<()>>,
}

impl Behind {
    /// Starts the helper. When no thread can start, the jobs run on the
    /// caller's thread as they are submitted.
    /// `checker` is an empty mapper with `mapper`'s options and cell size.
    fn start(mapper: Mapper, checker: Mapper) -> Self {
        let shared = Arc::new(Shared {
            mapper: Mutex::new(mapper),
            state: Mutex::new(Progress::default()),
            idle: Condvar::new(),
        });
        let (tx, rx) = sync_channel(QUEUE_LENGTH);
        let theirs = Arc::clone(&shared);
        let thread = std::thread::Builder::new()
            .name("ndtgrid-mapper".into())
            .spawn(move || serve(&theirs, rx))
            .ok();
        Self {
            shared,
            checker,
            jobs: thread.is_some().then_some(tx),
            thread,
        }
    }

    /// Queues `job` (runs it here when there is no helper).
    fn submit(&mut self, job: Job) {
        lock(&self.shared.state).pending += 1;
        let job = match &self.jobs {
            Some(tx) => match tx.send(job) {
                Ok(()) => return,
                Err(e) => e.0,
            },
            None => job,
        };
        let (tx, rx) = sync_channel(1);
        if tx.send(job).is_ok() {
            drop(tx);
            serve(&self.shared, rx);
        }
    }

    /// Waits until every queued job is done; the first error of one.
    fn wait(&self) -> MutexGuard<'_, Progress> {
        let mut progress = lock(&self.shared.state);
        while progress.pending > 0 {
            progress = self
                .shared
                .idle
                .wait(progress)
                .unwrap_or_else(|e| e.into_inner());
        }
        progress
    }
}

impl Drop for Behind {
    fn drop(&mut self) {
        // Hanging up ends the helper after the queued jobs.
        self.jobs = None;
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// The loop's mapper: updated in line, or behind the loop on a helper thread.
pub(crate) enum MapperHost {
    Inline(Mapper),
    Behind(Behind),
}

impl MapperHost {
    /// Hosts `mapper`, on a helper thread when `behind`.
    pub(crate) fn new(mapper: Mapper, behind: bool) -> Result<Self> {
        Ok(if behind {
            let checker = Mapper::new(mapper.grid().cell_size(), *mapper.filter().options())?;
            Self::Behind(Behind::start(mapper, checker))
        } else {
            Self::Inline(mapper)
        })
    }

    /// The checks of [`Mapper::insert_scan`] alone; changes nothing.
    pub(crate) fn check_scan(&self, ranges: &[f64], angles: &[f64], pose: Pose2) -> Result<()> {
        match self {
            Self::Inline(m) => m.check_scan(ranges, angles, pose),
            Self::Behind(b) => b.checker.check_scan(ranges, angles, pose),
        }
    }

    /// [`Mapper::insert_scan`], now or queued. A queued insertion is checked
    /// first; an error of an earlier queued job (none is expected: each was
    /// checked) is returned here and the scan is not queued.
    pub(crate) fn insert_scan(
        &mut self,
        ranges: &[f64],
        angles: &[f64],
        pose: Pose2,
    ) -> Result<()> {
        match self {
            Self::Inline(m) => m.insert_scan(ranges, angles, pose),
            Self::Behind(b) => {
                b.checker.check_scan(ranges, angles, pose)?;
                if let Some(e) = lock(&b.shared.state).error.take() {
                    return Err(e);
                }
                b.submit(Job::Insert {
                    ranges: ranges.to_vec(),
                    angles: angles.to_vec(),
                    pose,
                });
                Ok(())
            }
        }
    }

    /// [`Mapper::remove_cells`], now or queued.
    pub(crate) fn remove_cells(&mut self, keys: Vec<CellKey>) {
        match self {
            Self::Inline(m) => {
                m.remove_cells(&keys);
            }
            Self::Behind(b) => b.submit(Job::Remove(keys)),
        }
    }

    /// The mapper in line, without waiting (`None` behind the loop).
    pub(crate) fn inline(&self) -> Option<&Mapper> {
        match self {
            Self::Inline(m) => Some(m),
            Self::Behind(_) => None,
        }
    }

    /// The mapper, once every queued job is done.
    pub(crate) fn view(&self) -> MapperView<'_> {
        match self {
            Self::Inline(m) => MapperView::Inline(m),
            Self::Behind(b) => {
                drop(b.wait());
                MapperView::Locked(lock(&b.shared.mapper))
            }
        }
    }

    /// Whether the mapper runs behind the loop.
    pub(crate) fn is_behind(&self) -> bool {
        matches!(self, Self::Behind(_))
    }
}

impl Clone for MapperHost {
    fn clone(&self) -> Self {
        let mapper = self.view().clone();
        match self {
            Self::Inline(_) => Self::Inline(mapper),
            Self::Behind(b) => Self::Behind(Behind::start(mapper, b.checker.clone())),
        }
    }
}

impl fmt::Debug for MapperHost {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let kind = if self.is_behind() { "Behind" } else { "Inline" };
        f.debug_tuple(kind).field(&*self.view()).finish()
    }
}

/// A read-only view of the loop's mapper ([`crate::Odometry::mapper`]); the
/// helper thread waits while one is held.
pub enum MapperView<'a> {
    /// The mapper updated in line.
    Inline(&'a Mapper),
    /// The mapper updated behind the loop, every queued job done.
    Locked(MutexGuard<'a, Mapper>),
}

impl Deref for MapperView<'_> {
    type Target = Mapper;

    fn deref(&self) -> &Mapper {
        match self {
            Self::Inline(m) => m,
            Self::Locked(g) => g,
        }
    }
}
