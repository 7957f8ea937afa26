//! What a primitive is the surface of: one of the scene's materials, or a light's emitting
//! surface (an area light occludes and is seen like any shape, but reflects nothing). Kept in a
//! primitive as one `u32`, the top bit telling the two apart.

/// The top bit of an id marks a light's surface.
const EMITTER: u32 = 1 << 31;

/// What a ray hit belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Surface {
    /// A shape with the scene's material of this index.
    Material(usize),
    /// The surface of the scene's light of this index.
    Emitter(usize),
}

impl Surface {
    /// The id primitives keep. Panics past 2³¹ materials or lights, which no scene loader makes.
    pub(super) fn id(self) -> u32 {
        match self {
            Surface::Material(m) => u32::try_from(m).ok().filter(|&m| m < EMITTER).expect("material index"),
            Surface::Emitter(l) => u32::try_from(l).ok().filter(|&l| l < EMITTER).expect("light index") | EMITTER,
        }
    }

    /// The surface an id names.
    pub(super) fn from_id(id: u32) -> Self {
        if id & EMITTER != 0 { Surface::Emitter((id & !EMITTER) as usize) } else { Surface::Material(id as usize) }
    }

    /// The material's index, for a shape.
    #[must_use]
    pub fn material(self) -> Option<usize> {
        match self {
            Surface::Material(m) => Some(m),
            Surface::Emitter(_) => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_round_trip_and_keep_the_two_apart() {
        for s in [Surface::Material(0), Surface::Material(7), Surface::Emitter(0), Surface::Emitter(123_456)] {
            assert_eq!(Surface::from_id(s.id()), s);
        }
        assert_ne!(Surface::Material(3).id(), Surface::Emitter(3).id());
    }
}
