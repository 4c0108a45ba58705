!> PNG images for the figures: an indexed-colour (palette) PNG of a small integer image,
!> compressed by zlib (Debian's zlib1g, the library HDF5 already uses), and its base64
!> text for embedding in an SVG `<image>`. The format is the W3C PNG specification
!> (second edition): signature, IHDR, PLTE, IDAT (zlib stream of the scanlines, each
!> with its filter byte: 0 for the first, 2 (Up) for the others), IEND; each chunk with
!> its length and CRC-32 (zlib's crc32).
module femcod_png
   use, intrinsic :: iso_c_binding, only: c_char, c_int, c_long
   use, intrinsic :: iso_fortran_env, only: int64
   use femcod_zlib, only: c_compress2, c_compress_bound, c_crc32
   implicit none
   private
   public :: png_indexed, base64

contains

   !> The PNG file (its bytes) of `image(row, column)`, entries 0 .. size(palette, 2) - 1
   !> indexing `palette(1:3, :)` (red, green, blue, 0-255). Row 1 is the top row.
   !> `ok` is false if zlib fails (then `png` is empty).
   function png_indexed(image, palette, ok) result(png)
      integer, intent(in) :: image(:, :)
      integer, intent(in) :: palette(:, :)
      logical, intent(out) :: ok
      character(len=:), allocatable :: png
      character(kind=c_char), allocatable :: raw(:)
      character(len=:), allocatable :: packed, plte
      integer(c_long) :: packed_len
      integer :: rows, cols, i, j, k
      rows = size(image, 1)
      cols = size(image, 2)
      ! The scanlines: a filter byte, then one byte per pixel: the first row its palette
      ! indices (filter 0, none), every other row their differences from the row above
      ! modulo 256 (filter 2, "Up"): a smooth map (a gap map) becomes runs of small
      ! values. Deflated at level 1: three 1024^2 gap and pressure figures took 0.21 s
      ! and 320 + 180 kB, against 0.40 s and 300 + 130 kB at level 6 without the filter.
      ! Rows on all threads (into an array of bytes: gfortran 12 cannot share a
      ! deferred-length string between threads).
      allocate(raw(rows*(cols + 1)))
      !$omp parallel do private(j, k)
      do i = 1, rows
         k = (i - 1)*(cols + 1) + 1
         if (i == 1) then
            raw(k) = achar(0)
            do j = 1, cols
               raw(k + j) = achar(image(i, j))
            end do
         else
            raw(k) = achar(2)
            do j = 1, cols
               raw(k + j) = achar(modulo(image(i, j) - image(i - 1, j), 256))
            end do
         end if
      end do
      packed_len = c_compress_bound(int(size(raw), c_long))
      allocate(character(len=packed_len) :: packed)
      ok = c_compress2(packed, packed_len, raw, int(size(raw), c_long), 1_c_int) == 0
      png = ""
      if (.not. ok) return
      allocate(character(len=3*size(palette, 2)) :: plte)
      do k = 1, size(palette, 2)
         plte(3*k - 2:3*k) = achar(palette(1, k))//achar(palette(2, k))//achar(palette(3, k))
      end do
      ! Signature; IHDR: width, height, bit depth 8, colour type 3 (palette), deflate,
      ! filter method 0, no interlace.
      png = achar(137)//"PNG"//achar(13)//achar(10)//achar(26)//achar(10)// &
         chunk("IHDR", be32(int(cols, int64))//be32(int(rows, int64))//achar(8)//achar(3)//achar(0)//achar(0)// &
         achar(0))//chunk("PLTE", plte)//chunk("IDAT", packed(1:packed_len))//chunk("IEND", "")
   end function png_indexed

   !> A PNG chunk: length, type, data, CRC-32 of type and data.
   function chunk(kind, data) result(c)
      character(len=4), intent(in) :: kind
      character(len=*), intent(in) :: data
      character(len=:), allocatable :: c
      character(len=:), allocatable :: body
      integer(c_long) :: crc
      body = kind//data
      crc = c_crc32(0_c_long, body, int(len(body), c_int))
      c = be32(int(len(data), int64))//body//be32(int(crc, int64))
   end function chunk

   !> Four bytes, most significant first (of the low 32 bits of v).
   pure function be32(v) result(b)
      integer(int64), intent(in) :: v
      character(len=4) :: b
      integer :: k
      do k = 1, 4
         b(k:k) = achar(int(iand(shiftr(v, 8*(4 - k)), 255_int64)))
      end do
   end function be32

   !> RFC 4648 base64 of `bytes`, with padding, in one line.
   pure function base64(bytes) result(text)
      character(len=*), intent(in) :: bytes
      character(len=:), allocatable :: text
      character(len=*), parameter :: table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/"
      integer :: n, k, m, v, b1, b2, b3
      n = len(bytes)
      allocate(character(len=4*((n + 2)/3)) :: text)
      m = 0
      do k = 1, n, 3
         b1 = iachar(bytes(k:k))
         b2 = 0
         b3 = 0
         if (k + 1 <= n) b2 = iachar(bytes(k + 1:k + 1))
         if (k + 2 <= n) b3 = iachar(bytes(k + 2:k + 2))
         v = ior(ior(shiftl(b1, 16), shiftl(b2, 8)), b3)
         text(m + 1:m + 1) = table(iand(shiftr(v, 18), 63) + 1:iand(shiftr(v, 18), 63) + 1)
         text(m + 2:m + 2) = table(iand(shiftr(v, 12), 63) + 1:iand(shiftr(v, 12), 63) + 1)
         text(m + 3:m + 3) = table(iand(shiftr(v, 6), 63) + 1:iand(shiftr(v, 6), 63) + 1)
         text(m + 4:m + 4) = table(iand(v, 63) + 1:iand(v, 63) + 1)
         if (k + 1 > n) text(m + 3:m + 3) = "="
         if (k + 2 > n) text(m + 4:m + 4) = "="
         m = m + 4
      end do
   end function base64
end module femcod_png
