!> zlib (Debian's zlib1g, the library HDF5 already uses): the three functions femcod
!> calls, for the PNG figures (femcod_png) and for PREFIX.h5's deflated chunks
!> (femcod_hdf5). zlib's functions are thread-safe.
module femcod_zlib
   use, intrinsic :: iso_c_binding, only: c_char, c_int, c_long
   implicit none
   private
   public :: c_compress2, c_compress_bound, c_crc32

   interface
      !> int compress2(Bytef *dest, uLongf *destLen, const Bytef *source, uLong sourceLen, int level)
      function c_compress2(dest, dest_len, source, source_len, level) bind(c, name="compress2") result(rc)
         import :: c_char, c_long, c_int
         character(kind=c_char), intent(out) :: dest(*)
         integer(c_long), intent(inout) :: dest_len
         character(kind=c_char), intent(in) :: source(*)
         integer(c_long), value :: source_len
         integer(c_int), value :: level
         integer(c_int) :: rc
      end function c_compress2
      !> uLong compressBound(uLong sourceLen)
      function c_compress_bound(source_len) bind(c, name="compressBound") result(bound)
         import :: c_long
         integer(c_long), value :: source_len
         integer(c_long) :: bound
      end function c_compress_bound
      !> uLong crc32(uLong crc, const Bytef *buf, uInt len)
      function c_crc32(crc, buf, length) bind(c, name="crc32") result(next)
         import :: c_long, c_char, c_int
         integer(c_long), value :: crc
         character(kind=c_char), intent(in) :: buf(*)
         integer(c_int), value :: length
         integer(c_long) :: next
      end function c_crc32
   end interface
end module femcod_zlib
