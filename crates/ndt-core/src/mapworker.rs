//! The odometry loop's mapper (the §V elimination in front of its own grid),
//! updated on a helper thread behind the loop, or on the loop's own thread.
//!
//! The loop's poses do not depend on the mapper (unless it matches against
//! the filtered map), so its updates can run while the loop matches the next
//! scans: each insertion (with the removals it brings) is queued, in order,
//! to one helper thread, and reading the mapper waits until the queue is
//! empty. The mapper is then the same, bit for bit, as one updated in line.
//!
//! A queued insertion cannot fail: it is checked first, on the caller's
//! thread, against an empty mapper with the same options and cell size (the
//! checks of [`Mapper::insert_scan`] depend on nothing else), so a scan the
//! mapper would refuse is refused before anything changes.
//!
//! Scans are handed over 8 at a time (`BATCH_LENGTH`), and a batch brings
//! the mapper's coarser levels up to date once. On the loop's own thread
//! (`OdometryConfig::background_mapper` off) the scans are batched the same
//! way and each full batch runs at once, as a helper would run it: a scan
//! at a time, the coarser levels took 9 % of the Intel loop (callgrind,
//! benches/SPEED_LOG.md, session 25). Only a loop that matches against the
//! mapper's grid updates it scan by scan. A process that forks
//! keeps only the forking thread: in the child the helper is gone, so the
//! mapper is then updated in line, and batches the parent's helper still
//! held are reported as lost ([`NdtError::MapperLost`], by the next insert)
//! rather than waited for. Waiting for the helper before forking
//! ([`crate::Odometry::wait_for_mapper`]) loses nothing; Python's `Odometry`
//! does it before every fork.
//!
//! The map's memory bound ([`crate::window`], `OdometryConfig::map_window`)
//! is kept with the mapper: whoever takes a scan in records the cells it
//! hits (the cells its beams end in, which are those of the loop's staged
//! points) and drops the cells no kept scan hits. Behind the loop, that
//! bookkeeping is the helper's: on the first 3000 Intel scans the loop's
//! thread ran 2.7 % fewer instructions, and the default loop took about
//! 5 % less time (benches/SPEED_LOG.md, session 26).

use std::fmt;
use std::ops::Deref;
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};
use std::sync::{Arc, Condvar, Mutex, MutexGuard, RwLock, RwLockReadGuard};
use std::thread::JoinHandle;

use crate::error::{NdtError, Result};
use crate::key::CellKey;
use crate::mapper::CheckedScan;
use crate::mapper::Mapper;
use crate::scratch::KeyScratch;
use crate::se2::Pose2;
use crate::window::CellWindow;

/// Scans the loop collects before handing them to the helper at once: each
/// hand-over wakes the helper, which costs the loop a system call (about
/// 26 µs in a VM, measured by `perf` on the Intel log).
const BATCH_LENGTH: usize = 8;

/// Batches handed over before the loop waits for the helper (bounds its lag
/// and the copies of scans it holds).
const QUEUE_LENGTH: usize = 2;

/// Done batches kept for their storage (`Spare`): as many as can be on
/// their way at once.
const SPARE_BATCHES: usize = QUEUE_LENGTH + 2;

/// The map's memory bound: the cells of the mapper's last `size` scans (0:
/// every scan's).
#[derive(Debug, Clone)]
pub(crate) struct MapWindow {
    cells: CellWindow,
    size: usize,
    /// Finds a scan's repeated cells (reused from scan to scan).
    seen: KeyScratch,
}

impl MapWindow {
    fn new(size: usize) -> Self {
        Self {
            cells: CellWindow::default(),
            size,
            seen: KeyScratch::default(),
        }
    }

    /// Records the cells `scan` hits (on the lattice of cells `1 /
    /// inv_cell` wide); returns those no kept scan hits any more.
    fn record(&mut self, scan: &CheckedScan, inv_cell: f64) -> Vec<CellKey> {
        // Without a bound nothing is kept: the cells are not even computed.
        let cells = if self.size == 0 {
            Vec::new()
        } else {
            scan.cells(inv_cell, self.seen.take())
        };
        self.cells.record(cells, self.size)
    }
}

/// Batches the helper is done with, emptied, and their scans: the loop
/// takes the next ones' storage from them. Memory the loop's thread
/// allocated and the helper's thread freed made both threads wait for
/// glibc's lock of the loop's arena (benches/SPEED_LOG.md, session 27).
/// The loop makes a scan only when none is spare, so no more scans exist
/// than were once on their way at the same time (at most
/// `SPARE_BATCHES` batches).
struct Spare {
    batches: Vec<Vec<CheckedScan>>,
    scans: Vec<CheckedScan>,
}

impl Spare {
    /// Room for what `SPARE_BATCHES` batches hold, reserved now: keeping
    /// never grows these vectors.
    fn new() -> Self {
        Self {
            batches: Vec::with_capacity(SPARE_BATCHES),
            scans: Vec::with_capacity(SPARE_BATCHES * BATCH_LENGTH),
        }
    }

    /// Keeps a done batch's storage, up to the bounds (the rest is freed).
    fn keep(&mut self, mut batch: Vec<CheckedScan>) {
        let room = self.scans.capacity() - self.scans.len();
        let n = batch.len().min(room);
        self.scans.extend(batch.drain(..n));
        batch.clear();
        if self.batches.len() < self.batches.capacity() {
            self.batches.push(batch);
        }
    }
}

/// What the loop and the helper share.
struct Shared {
    /// Written by the helper only; read by views, which exist only while the
    /// helper has nothing to do (taking one waits for that, and the loop
    /// cannot hand over more while one is held), so views may nest.
    mapper: RwLock<Mapper>,
    /// Used by whoever holds `mapper` for writing.
    window: Mutex<MapWindow>,
    spare: Mutex<Spare>,
    state: Mutex<Progress>,
    idle: Condvar,
}

/// Batches handed over and not yet done, and the first error a job gave.
#[derive(Default)]
struct Progress {
    pending: usize,
    error: Option<NdtError>,
}

/// Marks a batch done when dropped, also when a job unwinds, so a reader
/// never waits for a batch that will not finish.
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

/// A checked scan into `mapper`, then the cells `window` drops after it:
/// what a job does, and what the loop does in line.
fn apply_scan(mapper: &mut Mapper, window: &mut MapWindow, scan: &CheckedScan) -> Result<()> {
    let stale = window.record(scan, 1.0 / mapper.grid().cell_size());
    let mut mapper = mapper.batch();
    mapper.insert_checked(scan)?;
    mapper.remove_cells(&stale);
    mapper.give_back(stale);
    Ok(())
}

/// Runs a batch of scans in order (the first error is kept, the other scans
/// still run), then keeps its storage for the loop.
fn serve_batch(shared: &Shared, batch: Vec<CheckedScan>) {
    let mut done = Done {
        shared,
        result: Ok(()),
    };
    let mut guard = shared.mapper.write().unwrap_or_else(|e| e.into_inner());
    let mut window = lock(&shared.window);
    // The batch's scans bring the coarser levels up to date once, at its
    // end (NdtGrid::deferral, crate/src/grid/deferral.rs): the same map, bit for bit.
    let mut mapper = guard.batch();
    for scan in &batch {
        let result = apply_scan(&mut mapper, &mut window, scan);
        if done.result.is_ok() {
            done.result = result;
        }
    }
    // The mapper is settled and unlocked before the batch counts as done.
    drop(mapper);
    drop(window);
    drop(guard);
    lock(&shared.spare).keep(batch);
}

/// The helper thread: runs the batches in order until the loop hangs up.
fn serve(shared: &Shared, batches: Receiver<Vec<CheckedScan>>) {
    for batch in batches {
        serve_batch(shared, batch);
    }
}

/// The mapper updated in batches: on a helper thread, or on the caller's.
pub(crate) struct Behind {
    shared: Arc<Shared>,
    /// An empty mapper with the same options and cell size: checks scans.
    checker: Mapper,
    /// Scans not yet handed over.
    batch: Mutex<Vec<CheckedScan>>,
    /// Spare scans taken from `Shared::spare` at once, for the loop's
    /// checks.
    scans: Mutex<Vec<CheckedScan>>,
    batches: Option<SyncSender<Vec<CheckedScan>>>,
    thread: Option<JoinHandle<()>>,
    /// The process the helper runs in (a forked child has no helper).
    pid: u32,
    /// A helper thread was asked for (else the batches run on the caller's
    /// thread).
    threaded: bool,
}

impl Behind {
    /// Starts the helper when `threaded`; `checker` is an empty mapper with
    /// `mapper`'s options and cell size; `window` the map's memory bound.
    /// Without a helper (not asked for, or no thread could start) the
    /// batches run on the caller's thread as they are handed over.
    fn start(mapper: Mapper, window: MapWindow, checker: Mapper, threaded: bool) -> Self {
        let shared = Arc::new(Shared {
            mapper: RwLock::new(mapper),
            window: Mutex::new(window),
            spare: Mutex::new(Spare::new()),
            state: Mutex::new(Progress::default()),
            idle: Condvar::new(),
        });
        let (tx, rx) = sync_channel(QUEUE_LENGTH);
        let theirs = Arc::clone(&shared);
        let thread = threaded
            .then(|| {
                std::thread::Builder::new()
                    .name("ndtgrid-mapper".into())
                    .spawn(move || serve(&theirs, rx))
                    .ok()
            })
            .flatten();
        Self {
            shared,
            checker,
            batch: Mutex::new(Vec::with_capacity(BATCH_LENGTH)),
            scans: Mutex::new(Vec::with_capacity(SPARE_BATCHES * BATCH_LENGTH)),
            batches: thread.is_some().then_some(tx),
            thread,
            pid: std::process::id(),
            threaded,
        }
    }

    /// The helper's queue, when the helper runs in this process.
    fn helper(&self) -> Option<&SyncSender<Vec<CheckedScan>>> {
        self.batches
            .as_ref()
            .filter(|_| std::process::id() == self.pid)
    }

    /// A spare scan for the next check: one of those the helper is done
    /// with, if any.
    fn spare_scan(&self) -> Option<CheckedScan> {
        let mut scans = lock(&self.scans);
        if scans.is_empty() {
            let mut spare = lock(&self.shared.spare);
            let n = spare.scans.len().min(scans.capacity());
            scans.extend(spare.scans.drain(..n));
        }
        scans.pop()
    }

    /// Adds `scan` to the batch, handing it over when full (the next batch
    /// in a done one's storage).
    fn submit(&mut self, scan: CheckedScan) {
        let batch = self.batch.get_mut().unwrap_or_else(|e| e.into_inner());
        batch.push(scan);
        if batch.len() >= BATCH_LENGTH {
            let next = lock(&self.shared.spare).batches.pop();
            let next = next.unwrap_or_else(|| Vec::with_capacity(BATCH_LENGTH));
            let full = std::mem::replace(batch, next);
            self.hand_over(full);
        }
    }

    /// Hands the scans not yet handed over to the helper.
    fn flush(&self) {
        let rest = std::mem::take(&mut *lock(&self.batch));
        if !rest.is_empty() {
            self.hand_over(rest);
        }
    }

    /// Queues `batch` (runs it here when there is no helper).
    fn hand_over(&self, batch: Vec<CheckedScan>) {
        lock(&self.shared.state).pending += 1;
        let batch = match self.helper() {
            Some(tx) => match tx.send(batch) {
                Ok(()) => return,
                Err(e) => e.0,
            },
            None => batch,
        };
        serve_batch(&self.shared, batch);
    }

    /// In a forked child, the batches the parent's helper held are lost:
    /// counted as done, with [`NdtError::MapperLost`] as the error.
    fn count_lost(&self, progress: &mut Progress) {
        if self.helper().is_none() && progress.pending > 0 {
            let batches = std::mem::take(&mut progress.pending);
            progress
                .error
                .get_or_insert(NdtError::MapperLost { batches });
        }
    }

    /// The first error a job gave (or a loss, see [`Behind::count_lost`]),
    /// taken; does not wait.
    fn take_error(&self) -> Option<NdtError> {
        let mut progress = lock(&self.shared.state);
        self.count_lost(&mut progress);
        progress.error.take()
    }

    /// Waits until every queued job is done.
    fn wait(&self) {
        let mut progress = lock(&self.shared.state);
        self.count_lost(&mut progress);
        while progress.pending > 0 {
            progress = self
                .shared
                .idle
                .wait(progress)
                .unwrap_or_else(|e| e.into_inner());
        }
    }
}

impl Drop for Behind {
    fn drop(&mut self) {
        // Hanging up ends the helper after the batches handed over (the
        // rest, unreadable now, is dropped).
        let here = std::process::id() == self.pid;
        self.batches = None;
        if let Some(thread) = self.thread.take() {
            if here {
                let _ = thread.join();
            } else {
                // A forked child: the thread is the parent's; only its
                // handle is here.
                std::mem::forget(thread);
            }
        }
    }
}

/// The loop's mapper: updated scan by scan in line, or in batches (behind
/// the loop on a helper thread, or on the loop's thread).
pub(crate) enum MapperHost {
    Inline(Mapper, MapWindow),
    Behind(Behind),
}

/// Where and how a [`MapperHost`] updates its mapper.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Hosting {
    /// Each scan at once, in line (a loop matching against the mapper's grid).
    EachScan,
    /// In batches on the loop's thread.
    Batches,
    /// In batches on a helper thread.
    Helper,
}

impl MapperHost {
    /// Hosts `mapper` as `hosting` says, keeping the cells of its last
    /// `window` scans (0: every scan's, see [`crate::window`]).
    pub(crate) fn new(mapper: Mapper, hosting: Hosting, window: usize) -> Result<Self> {
        let window = MapWindow::new(window);
        Ok(match hosting {
            Hosting::EachScan => Self::Inline(mapper, window),
            Hosting::Batches | Hosting::Helper => {
                let checker = Mapper::new(mapper.grid().cell_size(), *mapper.filter().options())?;
                let helper = hosting == Hosting::Helper;
                Self::Behind(Behind::start(mapper, window, checker, helper))
            }
        })
    }

    /// The checks of [`Mapper::insert_scan`] alone, and behind the loop the
    /// error an earlier job gave (none is expected: each was checked; a
    /// fork may lose batches), taken: the loop calls this before anything
    /// changes, so a refused scan leaves both maps as they were.
    pub(crate) fn check_scan(
        &self,
        ranges: &[f64],
        angles: &[f64],
        directions: Option<&[(f64, f64)]>,
        pose: Pose2,
    ) -> Result<CheckedScan> {
        match self {
            Self::Inline(m, _) => m.check_scan(ranges, angles, directions, pose, None),
            Self::Behind(b) => {
                let spare = b.spare_scan();
                let scan = b
                    .checker
                    .check_scan(ranges, angles, directions, pose, spare)?;
                b.take_error().map_or(Ok(scan), Err)
            }
        }
    }

    /// A scan [`MapperHost::check_scan`] passed into the mapper, then
    /// [`Mapper::remove_cells`] of the cells the map's memory bound drops:
    /// now, or queued as one job.
    pub(crate) fn update(&mut self, scan: CheckedScan) -> Result<()> {
        match self {
            Self::Inline(m, window) => apply_scan(m, window, &scan),
            Self::Behind(b) => {
                b.submit(scan);
                Ok(())
            }
        }
    }

    /// The mapper in line, without waiting (`None` behind the loop).
    pub(crate) fn inline(&self) -> Option<&Mapper> {
        match self {
            Self::Inline(m, _) => Some(m),
            Self::Behind(_) => None,
        }
    }

    /// The mapper, once every queued job is done.
    pub(crate) fn view(&self) -> MapperView<'_> {
        match self {
            Self::Inline(m, _) => MapperView::Inline(m),
            Self::Behind(b) => {
                self.settle();
                MapperView::Locked(b.shared.mapper.read().unwrap_or_else(|e| e.into_inner()))
            }
        }
    }

    /// Waits until the helper has taken in every scan (at once in line).
    pub(crate) fn settle(&self) {
        if let Self::Behind(b) = self {
            b.flush();
            b.wait();
        }
    }
}

impl Clone for MapperHost {
    fn clone(&self) -> Self {
        let mapper = self.view().clone();
        match self {
            Self::Inline(_, window) => Self::Inline(mapper, window.clone()),
            Self::Behind(b) => {
                // Settled by the view: no job holds the window.
                let window = lock(&b.shared.window).clone();
                Self::Behind(Behind::start(mapper, window, b.checker.clone(), b.threaded))
            }
        }
    }
}

impl fmt::Debug for MapperHost {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let kind = match self {
            Self::Inline(..) => "Inline",
            Self::Behind(b) if b.threaded => "Behind",
            Self::Behind(_) => "Batches",
        };
        f.debug_tuple(kind).field(&*self.view()).finish()
    }
}

/// A read-only view of the loop's mapper ([`crate::Odometry::mapper`]).
/// Views may be held together, also on one thread.
pub enum MapperView<'a> {
    /// The mapper updated in line.
    Inline(&'a Mapper),
    /// The mapper updated behind the loop, every queued job done.
    Locked(RwLockReadGuard<'a, Mapper>),
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

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::mapper::MapperOptions;

    /// The cells the map's window records for a checked scan are those the
    /// loop's grid gets from the same scan's points, in the same order: on
    /// random scans (invalid ranges among them) from random poses up to
    /// 400 m out, and on scans whose points lie on the cells' edges, with
    /// the beams' directions kept and computed.
    #[test]
    fn a_checked_scans_cells_are_its_points_cells() {
        use crate::ranges::BeamDirections;
        use crate::NdtGrid;
        use rand::rngs::StdRng;
        use rand::{Rng, SeedableRng};
        let mut rng = StdRng::seed_from_u64(26);
        // The loop's range limits (as `Odometry::new` gives them).
        let options = MapperOptions {
            min_range: 0.1,
            max_range: 30.0,
            ..MapperOptions::default()
        };
        let (lo, hi) = (options.min_range, options.max_range);
        let mut directions = BeamDirections::default();
        for trial in 0..300 {
            let cell = [0.02, 0.05, 0.1][trial % 3];
            let mapper = Mapper::new(cell, options).unwrap();
            let n = rng.random_range(1..400);
            // Every fourth trial on the cells' edges: beams along x from a
            // pose on a cell corner, ranges whole numbers of cells (as a
            // product, so some land an ulp short of the edge).
            let edges = trial % 4 == 3;
            let angles: Vec<f64> = (0..n)
                .map(|_| {
                    if edges {
                        0.0
                    } else {
                        rng.random_range(-3.2..3.2)
                    }
                })
                .collect();
            let ranges: Vec<f64> = (0..n)
                .map(|_| match rng.random_range(0..10) {
                    0 => f64::NAN,
                    1 => 0.0,
                    2 => hi + 1.0,
                    3 => lo * 0.5,
                    _ if edges => f64::from(rng.random_range(10..1000)) * cell,
                    _ => rng.random_range(lo..hi),
                })
                .collect();
            let pose = if edges {
                let corner = f64::from(rng.random_range(-9000..9000)) * cell;
                Pose2::new(corner, -corner, 0.0)
            } else {
                Pose2::new(
                    rng.random_range(-400.0..400.0),
                    rng.random_range(-400.0..400.0),
                    rng.random_range(-7.0..7.0),
                )
            };
            let points = directions.points(&ranges, &angles, lo, hi).unwrap();
            let kept = (trial % 2 == 0).then(|| directions.directions());
            let scan = mapper
                .check_scan(&ranges, &angles, kept, pose, None)
                .unwrap();
            let mut grid = NdtGrid::new(cell).unwrap();
            let staged = grid.insert(&points, pose).unwrap();
            assert!(!staged.is_empty() || points.is_empty());
            let mut seen = KeyScratch::default();
            assert_eq!(scan.cells(1.0 / cell, seen.take()), staged, "trial {trial}");
        }
    }

    /// A scan of a wall 1 m ahead, 41 beams.
    fn wall() -> (Vec<f64>, Vec<f64>) {
        let angles: Vec<f64> = (0..41).map(|i| (f64::from(i) - 20.0) * 0.01).collect();
        let ranges = angles.iter().map(|a| 1.0 / a.cos()).collect();
        (ranges, angles)
    }

    /// On the loop's thread the scans wait in a batch of 8 and no thread
    /// starts: a full batch is taken in at once, a read takes in the rest,
    /// and the mapper is the one updated scan by scan.
    #[test]
    fn batches_on_the_loops_thread_equal_each_scan_at_once() {
        let mapper = Mapper::new(0.02, MapperOptions::default()).unwrap();
        let mut batched = MapperHost::new(mapper.clone(), Hosting::Batches, 3).unwrap();
        let mut each = MapperHost::new(mapper, Hosting::EachScan, 3).unwrap();
        let threadless = match &batched {
            MapperHost::Behind(b) => b.thread.is_none() && !b.threaded,
            MapperHost::Inline(..) => false,
        };
        assert!(threadless, "batches are hosted as a threadless Behind");
        let (r, a) = wall();
        let taken = |host: &MapperHost| match host {
            MapperHost::Behind(b) => b.shared.mapper.read().unwrap().grid().len(),
            MapperHost::Inline(m, _) => m.grid().len(),
        };
        for k in 0..11 {
            let pose = Pose2::new(0.01 * f64::from(k), 0.0, 0.0);
            let scan = batched.check_scan(&r, &a, None, pose).unwrap();
            batched.update(scan).unwrap();
            let scan = each.check_scan(&r, &a, None, pose).unwrap();
            each.update(scan).unwrap();
            // Nothing until the eighth scan, then the first 8 at once.
            assert_eq!(taken(&batched) > 0, k >= 7, "scan {k}");
        }
        assert_eq!(
            batched.view().to_bytes().unwrap(),
            each.view().to_bytes().unwrap()
        );
        assert_eq!(taken(&batched), taken(&each));
        assert_eq!(format!("{batched:?}").split('(').next(), Some("Batches"));
    }

    /// The helper gives a done batch's scans and vector back, and the
    /// loop's next checks and batch take them; what is kept never grows.
    #[test]
    fn done_batches_come_back_to_the_loop() {
        let mapper = Mapper::new(0.02, MapperOptions::default()).unwrap();
        let mut host = MapperHost::new(mapper, Hosting::Helper, 4).unwrap();
        let (r, a) = wall();
        let pools = |host: &MapperHost| match host {
            MapperHost::Behind(b) => {
                let spare = b.shared.spare.lock().unwrap();
                let stash = b.scans.lock().unwrap();
                [
                    spare.scans.len(),
                    spare.batches.len(),
                    stash.len(),
                    spare.scans.capacity(),
                    spare.batches.capacity(),
                    stash.capacity(),
                ]
            }
            MapperHost::Inline(..) => [usize::MAX; 6],
        };
        let room = [SPARE_BATCHES * BATCH_LENGTH, SPARE_BATCHES];
        for k in 0..BATCH_LENGTH {
            let pose = Pose2::new(0.01 * k as f64, 0.0, 0.0);
            let scan = host.check_scan(&r, &a, None, pose).unwrap();
            host.update(scan).unwrap();
        }
        host.settle();
        assert_eq!(pools(&host), [8, 1, 0, room[0], room[1], room[0]]);
        let scan = host.check_scan(&r, &a, None, Pose2::identity()).unwrap();
        assert_eq!(pools(&host), [0, 1, 7, room[0], room[1], room[0]]);
        host.update(scan).unwrap();
        for k in 0..20 * BATCH_LENGTH {
            let pose = Pose2::new(0.001 * k as f64, 0.0, 0.0);
            let scan = host.check_scan(&r, &a, None, pose).unwrap();
            host.update(scan).unwrap();
        }
        host.settle();
        let [scans, batches, stash, cap_scans, cap_batches, cap_stash] = pools(&host);
        assert!(scans + stash <= room[0] && batches <= room[1]);
        assert_eq!(
            [cap_scans, cap_batches, cap_stash],
            [room[0], room[1], room[0]]
        );
    }
}
