//! Mesh files: OBJ (through tobj) and PLY (ASCII and binary, optionally gzip).
