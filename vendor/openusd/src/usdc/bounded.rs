//! ppis patch: bounded reads. A count read from a usdc file sizes an allocation only once the
//! file can back it, so a corrupt count is an error instead of an allocation of terabytes
//! (which aborts the process). Every bound follows from the format, never from a guess about
//! how well a valid file compresses:
//!
//! - an uncompressed array, or a list of items of a known least size, fits in the bytes that
//!   remain after its count;
//! - a compressed block lies within the file and decompresses into a buffer no larger than the
//!   size its reader expects (for integers, Pixar's working size `GetEncodedBufferSize`) and
//!   than LZ4 can produce from the block (at most 255 bytes of output per byte of input);
//! - `count` coded integers are decoded only from decoded bytes that can hold them: the common
//!   value, then 2 bits of code per integer (an integer equal to the common value takes no
//!   further bytes), so no valid file is refused however repetitive its integers are.

use std::{io, mem};

use anyhow::{ensure, Result};
use bytemuck::{cast_slice_mut, AnyBitPattern, NoUninit};
use num_traits::{AsPrimitive, PrimInt};

use super::{decompress_lz4, CrateFile, ReadExt};
use crate::usdc::coding;

/// LZ4 writes at most 255 bytes per byte of its input: each byte of a match-length or
/// literal-length extension adds at most 255, and a sequence's token and offset (3 bytes) at
/// most 19.
const LZ4_MAX_RATIO: u64 = 255;

/// Pixar's `_GetEncodedBufferSize<Int>(n)`: the common value, 2 bits of code per integer and
/// at most `size_of::<Int>()` bytes of data per integer.
fn encoded_buffer_size(int_size: u64, count: u64) -> u64 {
    if count == 0 {
        return 0;
    }
    int_size.saturating_add(count.saturating_mul(2).div_ceil(8)).saturating_add(count.saturating_mul(int_size))
}

/// The fewest decoded bytes that hold `count` coded integers: the common value and the codes.
fn least_encoded_size(int_size: u64, count: u64) -> u64 {
    if count == 0 {
        return 0;
    }
    int_size.saturating_add(count.saturating_mul(2).div_ceil(8))
}

impl<R: io::Read + io::Seek> CrateFile<R> {
    /// Bytes between the read position and the end of the stream.
    pub(super) fn remaining(&mut self) -> Result<u64> {
        let pos = self.reader.stream_position()?;
        let len = self.reader.seek(io::SeekFrom::End(0))?;
        self.reader.seek(io::SeekFrom::Start(pos))?;
        Ok(len.saturating_sub(pos))
    }

    /// A count of items that each take at least `least_item_size` bytes of what follows it.
    pub(super) fn read_count_of(&mut self, least_item_size: u64) -> Result<usize> {
        let count = self.reader.read_count()?;
        let remaining = self.remaining()?;
        ensure!(
            (count as u64).saturating_mul(least_item_size) <= remaining,
            "corrupt file: {count} items of at least {least_item_size} bytes cannot fit in the {remaining} bytes that remain"
        );
        Ok(count)
    }

    /// `count` plain values read as they are stored.
    pub(super) fn read_bounded_vec<T: Default + NoUninit + AnyBitPattern>(&mut self, count: usize) -> Result<Vec<T>> {
        let bytes = (count as u64).saturating_mul(mem::size_of::<T>() as u64);
        ensure!(
            bytes <= self.remaining()?,
            "corrupt file: an array of {count} elements runs past the end of the file"
        );
        self.reader.read_vec(count)
    }

    /// A compressed block (u64 size, then Pixar's LZ4 framing) decompressed into at most
    /// `max_size` bytes, allocated as `T`s; returns the decoded values (whole `T`s only) and
    /// the number of bytes decoded.
    fn read_lz4<T: Default + NoUninit + AnyBitPattern>(&mut self, max_size: u64) -> Result<(Vec<T>, u64)> {
        let compressed_size = self.reader.read_count()? as u64;
        ensure!(
            compressed_size <= self.remaining()?,
            "corrupt file: a compressed block of {compressed_size} bytes runs past the end of the file"
        );
        let mut input = vec![0_u8; compressed_size as usize];
        self.reader.read_exact(&mut input)?;
        let size = mem::size_of::<T>() as u64;
        let limit = max_size.min(LZ4_MAX_RATIO.saturating_mul(compressed_size));
        let mut output = vec![T::default(); limit.div_ceil(size) as usize];
        let bytes = &mut cast_slice_mut(&mut output)[..limit as usize];
        let decoded = decompress_lz4(&input, bytes)? as u64;
        output.truncate((decoded / size) as usize);
        Ok((output, decoded))
    }

    /// A compressed block that decompresses to exactly `count` values of `T`.
    pub(super) fn read_compressed<T: Default + NoUninit + AnyBitPattern>(&mut self, count: usize) -> Result<Vec<T>> {
        let want = (count as u64).saturating_mul(mem::size_of::<T>() as u64);
        let (values, decoded) = self.read_lz4::<T>(want)?;
        ensure!(
            decoded == want,
            "corrupt file: a compressed block holds {decoded} bytes, not the {want} bytes of {count} values"
        );
        Ok(values)
    }

    /// `count` integers in Pixar's integer coding (`Usd_IntegerCompression`, or
    /// `Usd_IntegerCompression64` for 64-bit integers), LZ4-compressed.
    pub(super) fn read_encoded_ints<T: PrimInt + 'static>(&mut self, count: usize) -> Result<Vec<T>>
    where
        i64: AsPrimitive<T>,
    {
        let int_size = mem::size_of::<T>() as u64;
        let (buffer, decoded) = self.read_lz4::<u8>(encoded_buffer_size(int_size, count as u64))?;
        let least = least_encoded_size(int_size, count as u64);
        ensure!(
            decoded >= least,
            "corrupt file: {count} integers cannot come out of {decoded} decoded bytes (they take at least {least})"
        );
        coding::decode_ints(&buffer, count)
    }
}
