//! Reading and writing the files LIGGGHTS and LAMMPS read and write: text
//! dumps (plain or gzip), data files, VTK, and printf-style number formats.
pub mod cfmt;
pub mod data;
pub mod dump;
pub mod vtk;
