//! How it works: the LCC quadtree coding (paper § 4.1). To be written.
