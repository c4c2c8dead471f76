//! What each §V step removed, counted over the life of a mapper.

/// Cumulative removals per §V step. Steps a-3, a-4 and b-2 drop *points*
/// of a new scan before they reach the map; for them both the points and the
/// cells they would have created are counted (distinct cells of the dropped
/// points that are not in the map after their scan). Steps b-1, c and d
/// delete *cells* already in the map.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct RemovalCounts {
    /// a-3: points behind the centre of mass of a small cluster.
    pub behind_com_points: u64,
    /// a-3: cells those points would have created.
    pub behind_com_cells: u64,
    /// a-4: points of a small cluster outside its forefront cell.
    pub forefront_points: u64,
    /// a-4: cells those points would have created.
    pub forefront_cells: u64,
    /// b-2: small-cluster points in Area 2 behind a former cell.
    pub backshift_points: u64,
    /// b-2: cells those points would have created.
    pub backshift_cells: u64,
    /// b-1: small-object cells deleted for never being seen from Area 1.
    pub area1_cells: u64,
    /// c: cells deleted for being observed in too few scans.
    pub observation_cells: u64,
    /// d: cells removed as free space by the radial confirmation.
    pub confirmation_cells: u64,
}

impl RemovalCounts {
    /// `(name, value)` for every counter, in step order (a-3, a-4, b-1, b-2,
    /// c, d); the names are the field names.
    pub fn entries(&self) -> [(&'static str, u64); 9] {
        [
            ("behind_com_points", self.behind_com_points),
            ("behind_com_cells", self.behind_com_cells),
            ("forefront_points", self.forefront_points),
            ("forefront_cells", self.forefront_cells),
            ("area1_cells", self.area1_cells),
            ("backshift_points", self.backshift_points),
            ("backshift_cells", self.backshift_cells),
            ("observation_cells", self.observation_cells),
            ("confirmation_cells", self.confirmation_cells),
        ]
    }
}
