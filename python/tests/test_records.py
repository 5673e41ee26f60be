"""The record framing of .sgrid archives (splinegrid.records), byte for byte as
core/io/record_file.h writes it: magic line, then per record uint32 LE length, uint32 LE
CRC-32 (zlib's), payload."""

import os
import struct
import zlib

import pytest

from splinegrid import records


def write(path, payloads):
    with records.RecordWriter(path) as writer:
        for payload in payloads:
            writer.append(payload)


def test_layout_is_magic_then_length_crc_payload(tmp_path):
    path = tmp_path / "a.sgrid"
    write(path, [b"abc", b""])
    data = path.read_bytes()
    assert data == (b"splinegrid-records\n" + struct.pack("<II", 3, 0x352441C2) + b"abc"
                    + struct.pack("<II", 0, 0))
    assert records.frame_record(b"abc") == data[len(records.MAGIC):len(records.MAGIC) + 11]


def test_crc_is_zlibs_ieee_polynomial():
    # The check value of CRC-32/ISO-HDLC, what core/io/record_file.h's Crc32 computes.
    assert zlib.crc32(b"123456789") == 0xCBF43926
    assert records.frame_record(b"123456789")[4:8] == struct.pack("<I", 0xCBF43926)


def test_round_trip_of_small_empty_and_large_records(tmp_path):
    payloads = [b"", b"x", bytes(range(256)) * 9, os.urandom(3 << 20)]
    path = tmp_path / "b.sgrid"
    write(path, payloads)
    assert list(records.read_records(path)) == payloads
    with records.RecordReader(path) as reader:
        for _ in reader:
            pass
        assert reader.record == len(payloads)
        assert reader.offset == path.stat().st_size


def test_a_file_cut_at_a_record_boundary_reads_as_a_shorter_file(tmp_path):
    path = tmp_path / "c.sgrid"
    write(path, [b"first", b"second"])
    data = path.read_bytes()
    path.write_bytes(data[:len(records.MAGIC) + 8 + 5])
    assert list(records.read_records(path)) == [b"first"]
    path.write_bytes(records.MAGIC)
    assert list(records.read_records(path)) == []


@pytest.mark.parametrize("cut, what", [(3, "the file ends 3 bytes into the 8-byte frame header"),
                                       (8 + 2, "truncated record: 2 of 6 payload bytes present")])
def test_a_torn_record_is_reported_with_its_index_and_offset(tmp_path, cut, what):
    path = tmp_path / "d.sgrid"
    write(path, [b"first", b"second"])
    second = len(records.MAGIC) + 8 + 5
    path.write_bytes(path.read_bytes()[:second + cut])
    reader = records.read_records(path)
    assert next(reader) == b"first"
    with pytest.raises(records.RecordFileError) as error:
        next(reader)
    assert str(error.value) == (f"record file '{path}': record 1 at byte offset {second}: "
                                + ("truncated record: " if cut == 3 else "") + what)
    assert (error.value.record, error.value.offset) == (1, second)


def test_a_damaged_payload_is_a_crc_mismatch(tmp_path):
    path = tmp_path / "e.sgrid"
    write(path, [b"payload"])
    data = bytearray(path.read_bytes())
    data[-1] ^= 0x01
    path.write_bytes(bytes(data))
    with pytest.raises(records.RecordFileError, match="record 0 at byte offset 19: CRC mismatch: "
                       r"stored 0x[0-9a-f]{8}, payload has 0x[0-9a-f]{8}"):
        list(records.read_records(path))


def test_a_length_over_the_limit_is_refused_before_reading(tmp_path):
    path = tmp_path / "f.sgrid"
    path.write_bytes(records.MAGIC + struct.pack("<II", 0xFFFFFFF0, 0))
    with pytest.raises(records.RecordFileError, match="announced length 4294967280 bytes exceeds "
                       "the limit of 67108864 bytes"):
        list(records.read_records(path))
    write(path, [b"12345"])
    with pytest.raises(records.RecordFileError, match="exceeds the limit of 4 bytes"):
        list(records.read_records(path, max_record_bytes=4))


def test_a_file_that_is_not_a_record_file_says_so(tmp_path):
    path = tmp_path / "grid.p2dfmt"
    path.write_bytes(b"1\n3 2\n0.0 1.0 2.0\n")
    with pytest.raises(records.RecordFileError, match="is not a record file"):
        records.RecordReader(path)
    path.write_bytes(b"")
    with pytest.raises(records.RecordFileError, match="is not a record file"):
        records.RecordReader(path)


def test_a_writer_left_by_an_exception_is_closed_without_sync(tmp_path):
    path = tmp_path / "g.sgrid"
    with pytest.raises(RuntimeError):
        with records.RecordWriter(path) as writer:
            writer.append(b"kept")
            raise RuntimeError("stop")
    assert list(records.read_records(path)) == [b"kept"]
    with pytest.raises(ValueError, match="is closed"):
        writer.append(b"late")
