//! Recordings and extrapolations written for other tools (ParaView's VTK XML files).

pub mod vtk;
