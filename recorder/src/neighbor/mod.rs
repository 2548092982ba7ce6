//! Broad phase: a cell grid, particles re-sorted in cell order, and a full Verlet list in CSR
//! form with each contact's history stored next to its entry.

mod cell_grid;
mod verlet_list;

pub use cell_grid::CellGrid;
pub(crate) use verlet_list::ListPieces;
pub use verlet_list::NeighborList;
