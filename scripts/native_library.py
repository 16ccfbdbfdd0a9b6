"""Reads what a shared library of another platform declares, without that platform: its
architecture, the libraries it links, the symbols it exports or leaves to the loader. For
scripts/wheel-check.py (a Python extension module: ELF .so, PE .pyd, Mach-O .so).
Layouts: ELF, the System V gABI and the LSB's symbol versioning (Elf64_Ehdr, Elf64_Shdr,
Elf64_Dyn, Elf64_Verneed/Vernaux); PE, Microsoft's "PE Format" (COFF header, PE32+ optional
header, section table, import and export directories); Mach-O, <mach-o/loader.h> and
<mach-o/nlist.h> (scripts/macho-check.py's read_header reads the header and load commands)."""
import importlib.util
import os
import struct

# the Mach-O reader of scripts/macho-check.py (a file name with a hyphen: loaded by path)
_spec = importlib.util.spec_from_file_location("macho_check", os.path.join(os.path.dirname(os.path.abspath(__file__)), "macho-check.py"))
macho = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(macho)

EM = {62: "x86_64", 183: "aarch64"}
SHT_DYNAMIC, SHT_DYNSYM, SHT_GNU_VERNEED = 6, 11, 0x6FFFFFFE
DT_NEEDED = 1
STB_GLOBAL, STB_WEAK, SHN_UNDEF = 1, 2, 0
IMAGE_FILE_MACHINE_AMD64, IMAGE_FILE_DLL, PE32_PLUS = 0x8664, 0x2000, 0x20B
MACHO_CPU = {macho.CPU["x86_64"]: "x86_64", macho.CPU["aarch64"]: "arm64"}
FAT_MAGIC = 0xCAFEBABE
MH_DYLIB, MH_BUNDLE = 6, 8
LC_SYMTAB, LC_DYLD_INFO, LC_DYLD_INFO_ONLY, LC_DYLD_CHAINED_FIXUPS = 0x2, 0x22, 0x80000022, 0x80000034
N_EXT, N_TYPE, N_SECT = 0x01, 0x0E, 0xE
BIND_SPECIAL_DYLIB_FLAT_LOOKUP = -2


class Library:
    """One library (one slice of a universal Mach-O file): `format` ("ELF", "PE", "Mach-O"),
    `arch`, `needed` (the libraries it links), `exports` (the symbols it defines for others),
    and per format: ELF `versions` (the symbol versions it needs, e.g. GLIBC_2.17); PE `dll`
    (a DLL, not a program); Mach-O `filetype`, `platform`, `minos` and `lookup`, the symbols
    dyld binds, each with the library it binds it from ("dynamic lookup": the flat namespace,
    any image loaded, i.e. the interpreter that loads the module)."""

    def __init__(self, format, arch, needed, exports, **details):
        self.format, self.arch, self.needed, self.exports = format, arch, needed, exports
        self.__dict__.update(details)


def _cstring(data, at):
    return data[at : data.index(b"\0", at)].decode()


def read_elf(data):
    if data[4] != 2 or data[5] != 1:
        raise ValueError("not a 64-bit little-endian ELF file")
    machine = struct.unpack_from("<H", data, 18)[0]
    shoff, = struct.unpack_from("<Q", data, 40)
    shentsize, shnum = struct.unpack_from("<2H", data, 58)
    # Elf64_Shdr: name, type, flags, addr, offset, size, link, info, addralign, entsize
    sections = [struct.unpack_from("<2I4Q2I2Q", data, shoff + k * shentsize) for k in range(shnum)]
    needed, versions, exports = [], set(), []
    for _name, kind, _flags, _addr, offset, size, link, info, _align, _entsize in sections:
        strings = sections[link][4]
        if kind == SHT_DYNAMIC:
            for at in range(offset, offset + size, 16):
                tag, value = struct.unpack_from("<qQ", data, at)
                if tag == DT_NEEDED:
                    needed.append(_cstring(data, strings + value))
        elif kind == SHT_DYNSYM:
            for at in range(offset, offset + size, 24):
                # Elf64_Sym: name, info, other, section index, value, size
                name, info, _other, section = struct.unpack_from("<IBBH", data, at)
                if section != SHN_UNDEF and info >> 4 in (STB_GLOBAL, STB_WEAK):
                    exports.append(_cstring(data, strings + name))
        elif kind == SHT_GNU_VERNEED:
            at = offset
            for _ in range(info):
                _version, count, _file, aux, following = struct.unpack_from("<2H3I", data, at)
                entry = at + aux
                for _ in range(count):
                    _hash, _vflags, _other, name, next_aux = struct.unpack_from("<I2H2I", data, entry)
                    versions.add(_cstring(data, strings + name))
                    entry += next_aux
                at += following
    return [Library("ELF", EM.get(machine, hex(machine)), needed, exports, versions=versions)]


def read_pe(data):
    pe = struct.unpack_from("<I", data, 0x3C)[0]
    if data[pe : pe + 4] != b"PE\0\0":
        raise ValueError("an MZ header without a PE signature")
    machine, nsections, _time, _symbols, _nsymbols, optional_size, characteristics = struct.unpack_from("<2H3I2H", data, pe + 4)
    optional = pe + 24
    if struct.unpack_from("<H", data, optional)[0] != PE32_PLUS:
        raise ValueError("not a PE32+ (64-bit) image")
    ndirectories = struct.unpack_from("<I", data, optional + 108)[0]
    directories = [struct.unpack_from("<2I", data, optional + 112 + 8 * k) for k in range(min(ndirectories, 2))]
    # each section: name, virtual size, virtual address, raw size, raw offset, ...
    sections = [struct.unpack_from("<8x4I", data, optional + optional_size + 40 * k) for k in range(nsections)]

    def offset(rva):
        for vsize, address, raw_size, raw in sections:
            if address <= rva < address + max(vsize, raw_size):
                return raw + rva - address
        raise ValueError(f"RVA {rva:#x} in no section")

    exports, needed = [], []
    export_rva, export_size = directories[0]
    if export_size:
        # IMAGE_EXPORT_DIRECTORY: ..., number of names at 24, the names' RVAs' array at 32
        count, names = struct.unpack_from("<I4xI", data, offset(export_rva) + 24)
        exports = [_cstring(data, offset(struct.unpack_from("<I", data, offset(names) + 4 * k)[0])) for k in range(count)]
    import_rva, import_size = directories[1] if len(directories) > 1 else (0, 0)
    if import_size:
        at = offset(import_rva)
        # IMAGE_IMPORT_DESCRIPTOR: lookup table, time, forwarder, name, address table; zeros end
        while any(struct.unpack_from("<5I", data, at)):
            needed.append(_cstring(data, offset(struct.unpack_from("<I", data, at + 12)[0])))
            at += 20
    arch = "x86_64" if machine == IMAGE_FILE_MACHINE_AMD64 else hex(machine)
    return [Library("PE", arch, needed, exports, dll=bool(characteristics & IMAGE_FILE_DLL))]


def _uleb(data, at):
    value = shift = 0
    while True:
        byte = data[at]
        at += 1
        value |= (byte & 0x7F) << shift
        shift += 7
        if byte < 0x80:
            return value, at


def _bind_ordinals(data, start, size):
    """{symbol: library ordinal} of a dyld bind opcode stream (<mach-o/loader.h>, BIND_OPCODE_*):
    the symbol and ordinal (BIND_SPECIAL_DYLIB_* negative) set when each DO_BIND* comes."""
    ordinals, ordinal, symbol, at, end = {}, 0, None, start, start + size
    while at < end:
        opcode, immediate = data[at] & 0xF0, data[at] & 0x0F
        at += 1
        if opcode in (0x90, 0xA0, 0xB0, 0xC0) and symbol is not None:  # DO_BIND*
            ordinals[symbol] = ordinal
        if opcode == 0x10:  # SET_DYLIB_ORDINAL_IMM
            ordinal = immediate
        elif opcode == 0x20:  # SET_DYLIB_ORDINAL_ULEB
            ordinal, at = _uleb(data, at)
        elif opcode == 0x30:  # SET_DYLIB_SPECIAL_IMM: 0, -1, -2, -3 as a 4-bit two's complement
            ordinal = immediate - 16 if immediate else 0
        elif opcode == 0x40:  # SET_SYMBOL_TRAILING_FLAGS_IMM, then the name
            name_end = data.index(b"\0", at)
            symbol = data[at:name_end].decode()
            at = name_end + 1
        elif opcode in (0x60, 0x70, 0x80, 0xA0):  # SET_ADDEND_SLEB, SET_SEGMENT_AND_OFFSET_ULEB, ADD_ADDR_ULEB, DO_BIND_ADD_ADDR_ULEB
            _, at = _uleb(data, at)
        elif opcode == 0xC0:  # DO_BIND_ULEB_TIMES_SKIPPING_ULEB
            _, at = _uleb(data, at)
            _, at = _uleb(data, at)
        elif opcode == 0xD0 and immediate == 0:  # THREADED, SET_BIND_ORDINAL_TABLE_SIZE_ULEB
            _, at = _uleb(data, at)
        # (DONE 0x00, SET_TYPE_IMM 0x50, DO_BIND 0x90, DO_BIND_ADD_ADDR_IMM_SCALED 0xB0 and
        # THREADED's APPLY carry no operand; DONE ends one symbol's run, not the stream)
    return ordinals


def _chained_import_ordinals(data, start):
    """{symbol: library ordinal} of the imports table of LC_DYLD_CHAINED_FIXUPS
    (<mach-o/fixup-chains.h>: dyld_chained_fixups_header, DYLD_CHAINED_IMPORT{,_ADDEND,_ADDEND64})."""
    _version, _starts, imports, symbols, count, imports_format, _symbols_format = struct.unpack_from("<7I", data, start)
    ordinals = {}
    for k in range(count):
        if imports_format == 3:
            entry = struct.unpack_from("<Q", data, start + imports + 16 * k)[0]
            ordinal, name = entry & 0xFFFF, entry >> 32
            ordinal = ordinal - 0x10000 if ordinal >= 0xFFF0 else ordinal
        else:
            entry = struct.unpack_from("<I", data, start + imports + (4 if imports_format == 1 else 8) * k)[0]
            ordinal, name = entry & 0xFF, entry >> 9
            ordinal = ordinal - 0x100 if ordinal >= 0xF0 else ordinal
        ordinals[_cstring(data, start + symbols + name)] = ordinal
    return ordinals


def _macho_slice(data, at):
    header = macho.read_header(data, at)
    if header is None:
        raise ValueError(f"no 64-bit Mach-O header at {at}")
    cputype, filetype, platform, minos, dylibs = header
    _magic, _cpu, _sub, _filetype, ncmds = struct.unpack_from("<5I", data, at)
    pos, exports, ordinals = at + 32, [], {}
    for _ in range(ncmds):
        cmd, size = struct.unpack_from("<2I", data, pos)
        if cmd == LC_SYMTAB:
            symoff, nsyms, stroff, _strsize = struct.unpack_from("<4I", data, pos + 8)
            for k in range(nsyms):
                # nlist_64: string index, type, section, description, value
                strx, kind, _sect, _desc, _value = struct.unpack_from("<IBBHQ", data, at + symoff + 16 * k)
                if kind & N_EXT and kind & N_TYPE == N_SECT:
                    exports.append(_cstring(data, at + stroff + strx))
        elif cmd in (LC_DYLD_INFO, LC_DYLD_INFO_ONLY):
            # rebase, bind, weak bind, lazy bind, export: (offset, size) each
            streams = struct.unpack_from("<10I", data, pos + 8)
            for offset, length in (streams[2:4], streams[4:6], streams[6:8]):
                ordinals.update(_bind_ordinals(data, at + offset, length))
        elif cmd == LC_DYLD_CHAINED_FIXUPS:
            offset, _length = struct.unpack_from("<2I", data, pos + 8)
            ordinals.update(_chained_import_ordinals(data, at + offset))
        pos += size

    def source(ordinal):
        if ordinal == BIND_SPECIAL_DYLIB_FLAT_LOOKUP:
            return "dynamic lookup"
        return dylibs[ordinal - 1] if 0 < ordinal <= len(dylibs) else f"ordinal {ordinal}"

    lookup = {name: source(ordinal) for name, ordinal in ordinals.items()}
    arch = MACHO_CPU.get(cputype, hex(cputype))
    return Library("Mach-O", arch, dylibs, exports, filetype=filetype, platform=platform, minos=minos, lookup=lookup)


def read_macho(data):
    if struct.unpack_from(">I", data, 0)[0] != FAT_MAGIC:
        return [_macho_slice(data, 0)]
    slices = []
    for k in range(struct.unpack_from(">I", data, 4)[0]):
        cputype, _sub, offset = struct.unpack_from(">3I", data, 8 + 20 * k)
        library = _macho_slice(data, offset)
        if library.arch != MACHO_CPU.get(cputype, hex(cputype)):
            raise ValueError(f"the universal header says {MACHO_CPU.get(cputype)} at {offset}, the slice there is {library.arch}")
        slices.append(library)
    return slices


def read(data):
    """The libraries of `data` (one, or a universal Mach-O file's slices); ValueError when it
    is none of the three formats or malformed."""
    try:
        if data[:4] == b"\x7fELF":
            return read_elf(data)
        if data[:2] == b"MZ":
            return read_pe(data)
        if struct.unpack_from("<I", data, 0)[0] == macho.MH_MAGIC_64 or struct.unpack_from(">I", data, 0)[0] == FAT_MAGIC:
            return read_macho(data)
    except (struct.error, IndexError) as error:
        raise ValueError(f"malformed: {error}") from error
    raise ValueError(f"neither ELF, PE nor Mach-O (first bytes {data[:4].hex()})")
