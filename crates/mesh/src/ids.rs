//! Typed `u32` ids. Half the memory of `usize`, and the type says which
//! array an id indexes.

macro_rules! id_type {
    ($(#[$m:meta])* $name:ident) => {
        $(#[$m])*
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
        #[derive(bytemuck::Pod, bytemuck::Zeroable)]
        #[repr(transparent)]
        pub struct $name(u32);
        impl $name {
            /// From its raw `u32` (file formats, flat arrays).
            #[inline(always)]
            pub const fn from_raw(i: u32) -> Self {
                $name(i)
            }
            /// Its raw `u32`.
            #[inline(always)]
            pub const fn raw(self) -> u32 {
                self.0
            }
            /// As an array index.
            #[inline(always)]
            pub fn idx(self) -> usize {
                self.0 as usize
            }
            /// From an array index (below `u32::MAX`).
            #[inline(always)]
            pub fn new(i: usize) -> Self {
                debug_assert!(i < u32::MAX as usize);
                $name(i as u32)
            }
        }
        impl std::fmt::Display for $name {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                write!(f, "{}", self.0)
            }
        }
    };
}

id_type!(
    /// Index into the point array.
    PointId
);
id_type!(
    /// Index into the tet array.
    TetId
);
id_type!(
    /// A tet face as `4*t + f`, `f` the local face (opposite vertex `f`).
    FaceRef
);

/// `neigh` entry of a face with no tet on the other side (boundary or front).
pub const NO_FACE: FaceRef = FaceRef(u32::MAX);

impl FaceRef {
    /// Face `f` (0 to 3) of tet `t`.
    #[inline(always)]
    pub fn of(t: TetId, f: usize) -> FaceRef {
        FaceRef(t.0 * 4 + f as u32)
    }
    /// The tet.
    #[inline(always)]
    pub fn tet(self) -> TetId {
        TetId(self.0 >> 2)
    }
    /// The local face, 0 to 3 (opposite vertex `f`).
    #[inline(always)]
    pub fn local(self) -> usize {
        (self.0 & 3) as usize
    }
    /// Whether it is [`NO_FACE`].
    #[inline(always)]
    pub fn is_none(self) -> bool {
        self == NO_FACE
    }
}
