#pragma once
// Reading the fields of a session part's JSON with a sentence for every problem: each reader
// looks its key up, leaves `out` as it is when an optional key is absent, and returns false
// with "WHERE KEY is missing" or "WHERE KEY must be KIND" in *why otherwise. JSON has no NaN:
// numbers are written with jsonNumber (non-finite as null) and null reads back as NaN.
#include <string>

#include <nlohmann/json.hpp>

namespace flexarm {

nlohmann::json jsonNumber(double v);

bool readNumber(const nlohmann::json& j, const char* key, double& out, bool required,
                std::string* why, const std::string& where);
bool readText(const nlohmann::json& j, const char* key, std::string& out, bool required,
              std::string* why, const std::string& where);
bool readFlag(const nlohmann::json& j, const char* key, bool& out, std::string* why,
              const std::string& where);
bool readWhole(const nlohmann::json& j, const char* key, int& out, std::string* why,
               const std::string& where);

// An exception of the JSON library as a sentence: without its "[json.exception.type_error.302]"
// prefix, at most 160 characters.
std::string jsonErrorText(const nlohmann::json::exception& e);

}  // namespace flexarm
