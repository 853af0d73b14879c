//! Asset libraries made into `catalog.json` catalogues (the schema is
//! [`lfformat::catalog`]): [`sweethome3d`] converts Sweet Home 3D's furniture libraries
//! (`lfgen assets fetch sweethome3d`).

pub mod sweethome3d;
